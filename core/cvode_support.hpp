#pragma once
/// SUNDIALS CVODE plumbing shared by core's free-motion integrators (core/simulate.cpp, the
/// reduced equation in theta1; core/opened_loop_dae.cpp, the opened loop's DAE). Internal to core.
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>

#include <stdexcept>
#include <string>

namespace bd::core::cvode {

/// The SUNDIALS objects of one integration, freed in reverse order of creation. Members left
/// null are not used by that integrator.
struct Session {
  SUNContext context{};
  N_Vector y{}, atol{};
  SUNMatrix matrix{};
  SUNLinearSolver linear{};
  SUNNonlinearSolver nonlinear{};
  void* memory{};
  Session() = default;
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  ~Session() {
    if (memory != nullptr) CVodeFree(&memory);
    if (nonlinear != nullptr) SUNNonlinSolFree(nonlinear);
    if (linear != nullptr) SUNLinSolFree(linear);
    if (matrix != nullptr) SUNMatDestroy(matrix);
    if (atol != nullptr) N_VDestroy(atol);
    if (y != nullptr) N_VDestroy(y);
    if (context != nullptr) SUNContext_Free(&context);
  }
};

/// With valid options the setup calls cannot fail except by running out of memory.
/// @throws std::runtime_error naming the call unless flag == CV_SUCCESS.
inline void check_setup(int flag, const char* call) {
  if (flag != CV_SUCCESS) throw std::runtime_error(std::string("CVODE setup failed in ") + call);
}

/// CVODE's error handler (CVodeSetErrHandlerFn) with `text` a std::string*: CVODE prints its
/// errors by default and core never prints, so the last error's text is kept for the message.
/// Warnings (error_code >= 0, e.g. t + h == t) are not failures and are dropped.
inline void keep_error(int error_code, const char* /*module*/, const char* function, char* msg,
                       void* text) {
  if (error_code >= 0) return;
  *static_cast<std::string*>(text) = std::string(function) + ": " + msg;
}

}  // namespace bd::core::cvode
