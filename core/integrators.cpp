#include "core/integrators.hpp"

#include <arkode/arkode.h>
#include <arkode/arkode_butcher_erk.h>
#include <arkode/arkode_erkstep.h>
#include <cvodes/cvodes.h>
#include <cvodes/cvodes_ls.h>
#include <cvodes/cvodes_proj.h>
#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_config.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace bd::core::integrators {

namespace {

// With a valid problem the setup calls cannot fail except by running out of memory.
void check_setup(int flag, const char* call) {
  // CV_SUCCESS, ARK_SUCCESS and IDA_SUCCESS are all 0
  if (flag != 0) throw std::runtime_error(std::string("SUNDIALS setup failed in ") + call);
}

void check_allocated(const void* object, const char* call) {
  if (object == nullptr) throw std::runtime_error(std::string("SUNDIALS setup failed in ") + call);
}

// The error handler of all three packages (CVErrHandlerFn, ARKErrHandlerFn, IDAErrHandlerFn
// share the signature), with `text` a std::string*: SUNDIALS prints its errors by default and
// core never prints, so the last error's text is kept for the message. Warnings
// (error_code >= 0, e.g. t + h == t) are not failures and are dropped.
void keep_error(int error_code, const char* /*module*/, const char* function, char* msg,
                void* text) {
  if (error_code >= 0) return;
  *static_cast<std::string*>(text) = std::string(function) + ": " + msg;
}

// The embedded pair of an ERK integrator (arkode/arkode_butcher_erk.h). The method order q is
// the first number after the stage count; the solution is advanced with the order-q formula
// and the embedding (order q - 1) only estimates the error (local extrapolation).
ARKODE_ERKTableID erk_table(Integrator integrator) {
  switch (integrator) {
    case Integrator::kErk2:
      return ARKODE_HEUN_EULER_2_1_2;
    case Integrator::kErk3:
      return ARKODE_BOGACKI_SHAMPINE_4_2_3;
    case Integrator::kErk4:
      return ARKODE_ZONNEVELD_5_3_4;
    case Integrator::kErk5:
      return ARKODE_DORMAND_PRINCE_7_4_5;
    case Integrator::kErk6:
      return ARKODE_VERNER_8_5_6;
    case Integrator::kErk8:
      return ARKODE_FEHLBERG_13_7_8;
    default:
      return ARKODE_ERK_NONE;
  }
}

// The table of an ERK integrator. SUNDIALS before 6.6 takes every table whose last node c_s is 1
// for "first same as last" (FSAL) and reuses its last stage's f as f(y_{n+1}) (llnl/sundials
// issue #311, fixed in 6.6.0). For the tables where that is false (Heun-Euler 2(1), Verner 6(5),
// Fehlberg 8(7)) the next step then starts from a wrong slope: with fixed steps Verner 6(5)
// converges at order 3, while the same table in a plain Runge-Kutta loop gives order 6
// (tests/core/integrators_test.cpp checks every pair's order). Such a table gets one more
// stage, y_{n+1} itself (row b, node 1, weight 0), which makes it FSAL in truth: the same method
// at the same cost (s right-hand sides per step, f(y_{n+1}) computed once).
ARKodeButcherTable erk_butcher_table(Integrator integrator) {
  ARKodeButcherTable table = ARKodeButcherTable_LoadERK(erk_table(integrator));
  check_allocated(table, "ARKodeButcherTable_LoadERK");
#if SUNDIALS_VERSION_MAJOR < 6 || (SUNDIALS_VERSION_MAJOR == 6 && SUNDIALS_VERSION_MINOR < 6)
  const int s = table->stages;
  bool fsal = true;
  for (int j = 0; j < s; ++j) fsal = fsal && std::abs(table->A[s - 1][j] - table->b[j]) <= 1e-14;
  if (table->c[s - 1] == 1.0 && !fsal) {
    ARKodeButcherTable extended = ARKodeButcherTable_Alloc(s + 1, SUNTRUE);
    if (extended == nullptr) ARKodeButcherTable_Free(table);
    check_allocated(extended, "ARKodeButcherTable_Alloc");
    extended->q = table->q;
    extended->p = table->p;
    for (int i = 0; i <= s; ++i) {
      for (int j = 0; j <= s; ++j) {
        extended->A[i][j] = i < s && j < s ? table->A[i][j] : i == s && j < s ? table->b[j] : 0.0;
      }
      extended->c[i] = i < s ? table->c[i] : 1.0;
      extended->b[i] = i < s ? table->b[i] : 0.0;
      extended->d[i] = i < s ? table->d[i] : 0.0;
    }
    ARKodeButcherTable_Free(table);
    return extended;
  }
#endif
  return table;
}

// a SUNDIALS return-flag name (the Get...ReturnFlagName functions malloc their result)
std::string flag_name(char* name) {
  std::string text = name != nullptr ? name : "unknown flag";
  std::free(name);
  return text;
}

N_Vector vector_of(const std::vector<double>& values, SUNContext context, const char* what) {
  N_Vector v = N_VNew_Serial(static_cast<sunindextype>(values.size()), context);
  check_allocated(v, what);
  double* data = N_VGetArrayPointer(v);
  for (std::size_t i = 0; i < values.size(); ++i) data[i] = values[i];
  return v;
}

}  // namespace

Integration::Integration(const Problem& p)
    : package_(p.integrator == Integrator::kIda ? Package::kIda
               : p.integrator == Integrator::kCvodeAdams || p.integrator == Integrator::kCvodeBdf
                   ? Package::kCvode
                   : Package::kArkode),
      stop_at_outputs_(p.integrator == Integrator::kErk6 || p.integrator == Integrator::kErk8),
      max_steps_(p.max_steps),
      t_(p.t0) {
  assert(p.absolute_tolerance.size() == p.y0.size());
  check_setup(SUNContext_Create(nullptr, &context_), "SUNContext_Create");
  y_ = vector_of(p.y0, context_, "N_VNew_Serial");
  atol_ = vector_of(p.absolute_tolerance, context_, "N_VNew_Serial");

  switch (package_) {
    case Package::kCvode:
      set_up_cvode(p);
      if (!p.sensitivities.which.empty()) set_up_sensitivities(p);
      break;
    case Package::kArkode:
      set_up_arkode(p);
      break;
    case Package::kIda:
      set_up_ida(p);
      break;
  }
}

void Integration::set_up_cvode(const Problem& p) {
  // Adams-Moulton (orders 1-12) with a fixed-point corrector: no Jacobian, one or two
  // right-hand sides per step on a non-stiff problem. BDF (orders 1-5) with a Newton
  // corrector: dense linear solver, Jacobian by SUNDIALS' difference quotients.
  const bool bdf = p.integrator == Integrator::kCvodeBdf;
  memory_ = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, context_);
  check_allocated(memory_, "CVodeCreate");
  check_setup(CVodeSetErrHandlerFn(memory_, keep_error, &error_text_), "CVodeSetErrHandlerFn");
  check_setup(CVodeInit(memory_, p.rhs, p.t0, y_), "CVodeInit");
  check_setup(CVodeSetUserData(memory_, p.user_data), "CVodeSetUserData");
  check_setup(CVodeSVtolerances(memory_, p.tolerance, atol_), "CVodeSVtolerances");
  if (bdf) {
    set_up_dense_solver(p);
    check_setup(CVodeSetLinearSolver(memory_, linear_, matrix_), "CVodeSetLinearSolver");
    if (p.projection != nullptr) {
      check_setup(CVodeSetProjFn(memory_, p.projection), "CVodeSetProjFn");
    }
  } else {
    assert(p.projection == nullptr);  // CVODE projects only with BDF
    nonlinear_ = SUNNonlinSol_FixedPoint(y_, 0, context_);
    check_allocated(nonlinear_, "SUNNonlinSol_FixedPoint");
    check_setup(CVodeSetNonlinearSolver(memory_, nonlinear_), "CVodeSetNonlinearSolver");
  }
  check_setup(CVodeSetStopTime(memory_, p.t_end), "CVodeSetStopTime");
  if (p.root != nullptr) check_setup(CVodeRootInit(memory_, 1, p.root), "CVodeRootInit");
}

void Integration::set_up_sensitivities(const Problem& p) {
  const Problem::Sensitivities& s = p.sensitivities;
  assert(s.parameters != nullptr && s.scales.size() == s.which.size());
  sensitivity_count_ = static_cast<int>(s.which.size());
  sensitivities_ = N_VCloneVectorArray(sensitivity_count_, y_);
  check_allocated(sensitivities_, "N_VCloneVectorArray");
  assert(s.initial.empty() || s.initial.size() == s.which.size());
  for (int i = 0; i < sensitivity_count_; ++i) {
    if (s.initial.empty()) {
      N_VConst(0.0, sensitivities_[i]);
      continue;
    }
    const std::vector<double>& s0 = s.initial[static_cast<std::size_t>(i)];
    assert(static_cast<sunindextype>(s0.size()) == N_VGetLength(y_));
    std::copy(s0.begin(), s0.end(), N_VGetArrayPointer(sensitivities_[i]));
  }
  parameter_scales_ = s.scales;
  parameter_list_ = s.which;
  // staggered corrector: the state's step is converged first, then the sensitivities' on the
  // same step, by the state's kind of iteration (fixed point for Adams, Newton for BDF with the
  // same dense linear solver)
  check_setup(CVodeSensInit(memory_, sensitivity_count_, CV_STAGGERED, nullptr, sensitivities_),
              "CVodeSensInit");
  check_setup(
      CVodeSetSensParams(memory_, s.parameters, parameter_scales_.data(), parameter_list_.data()),
      "CVodeSetSensParams");
  // centred differences along (s_i, e_i) at once (DQrhomax = 0), increments ~sqrt(rtol):
  // truncation ~rtol relative, below the integration error
  check_setup(CVodeSetSensDQMethod(memory_, CV_CENTERED, 0.0), "CVodeSetSensDQMethod");
  std::vector<double> absolute(s.which.size());
  const double* atol = N_VGetArrayPointer(atol_);
  const double atol_min = *std::min_element(atol, atol + N_VGetLength(atol_));
  for (std::size_t i = 0; i < absolute.size(); ++i) absolute[i] = atol_min / s.scales[i];
  check_setup(CVodeSensSStolerances(memory_, s.tolerance, absolute.data()),
              "CVodeSensSStolerances");
  check_setup(CVodeSetSensErrCon(memory_, SUNTRUE), "CVodeSetSensErrCon");
  if (p.integrator == Integrator::kCvodeAdams) {
    sensitivity_nonlinear_ = SUNNonlinSol_FixedPointSens(sensitivity_count_, y_, 0, context_);
    check_allocated(sensitivity_nonlinear_, "SUNNonlinSol_FixedPointSens");
    check_setup(CVodeSetNonlinearSolverSensStg(memory_, sensitivity_nonlinear_),
                "CVodeSetNonlinearSolverSensStg");
  }
}

const double* Integration::sensitivity(int i) const {
  assert(i >= 0 && i < sensitivity_count_);
  return N_VGetArrayPointer(sensitivities_[i]);
}

void Integration::set_up_arkode(const Problem& p) {
  assert(p.projection == nullptr);
  memory_ = ERKStepCreate(p.rhs, p.t0, y_, context_);
  check_allocated(memory_, "ERKStepCreate");
  check_setup(ERKStepSetErrHandlerFn(memory_, keep_error, &error_text_), "ERKStepSetErrHandlerFn");
  check_setup(ERKStepSetUserData(memory_, p.user_data), "ERKStepSetUserData");
  check_setup(ERKStepSVtolerances(memory_, p.tolerance, atol_), "ERKStepSVtolerances");
  // the table is copied by ERKStep
  ARKodeButcherTable table = erk_butcher_table(p.integrator);
  const int flag = ERKStepSetTable(memory_, table);
  ARKodeButcherTable_Free(table);
  check_setup(flag, "ERKStepSetTable");
  if (p.fixed_step > 0)
    check_setup(ERKStepSetFixedStep(memory_, p.fixed_step), "ERKStepSetFixedStep");
  check_setup(ERKStepSetStopTime(memory_, p.t_end), "ERKStepSetStopTime");
  if (p.root != nullptr) check_setup(ERKStepRootInit(memory_, 1, p.root), "ERKStepRootInit");
}

void Integration::set_up_ida(const Problem& p) {
  assert(p.yp0.size() == p.y0.size() && p.differential.size() == p.y0.size());
  assert(p.root == nullptr && p.projection == nullptr);
  yp_ = vector_of(p.yp0, context_, "N_VNew_Serial");
  std::vector<double> id(p.y0.size());
  for (std::size_t i = 0; i < id.size(); ++i) id[i] = p.differential[i] ? 1.0 : 0.0;
  id_ = vector_of(id, context_, "N_VNew_Serial");
  memory_ = IDACreate(context_);
  check_allocated(memory_, "IDACreate");
  check_setup(IDASetErrHandlerFn(memory_, keep_error, &error_text_), "IDASetErrHandlerFn");
  check_setup(IDAInit(memory_, p.residual, p.t0, y_, yp_), "IDAInit");
  check_setup(IDASetUserData(memory_, p.user_data), "IDASetUserData");
  check_setup(IDASVtolerances(memory_, p.tolerance, atol_), "IDASVtolerances");
  // the algebraic components (multipliers) take no part in the local error test: in an
  // index-2 system their error is of lower order and would only hold the step back
  check_setup(IDASetId(memory_, id_), "IDASetId");
  check_setup(IDASetSuppressAlg(memory_, SUNTRUE), "IDASetSuppressAlg");
  set_up_dense_solver(p);
  check_setup(IDASetLinearSolver(memory_, linear_, matrix_), "IDASetLinearSolver");
  check_setup(IDASetStopTime(memory_, p.t_end), "IDASetStopTime");
  if (p.initial_step > 0) check_setup(IDASetInitStep(memory_, p.initial_step), "IDASetInitStep");
}

void Integration::set_up_dense_solver(const Problem& p) {
  const auto n = static_cast<sunindextype>(p.y0.size());
  matrix_ = SUNDenseMatrix(n, n, context_);
  check_allocated(matrix_, "SUNDenseMatrix");
  linear_ = SUNLinSol_Dense(y_, matrix_, context_);
  check_allocated(linear_, "SUNLinSol_Dense");
}

Integration::~Integration() {
  if (memory_ != nullptr) {
    switch (package_) {
      case Package::kCvode:
        CVodeFree(&memory_);
        break;
      case Package::kArkode:
        ERKStepFree(&memory_);
        break;
      case Package::kIda:
        IDAFree(&memory_);
        break;
    }
  }
  if (sensitivity_nonlinear_ != nullptr) SUNNonlinSolFree(sensitivity_nonlinear_);
  if (sensitivities_ != nullptr) N_VDestroyVectorArray(sensitivities_, sensitivity_count_);
  if (nonlinear_ != nullptr) SUNNonlinSolFree(nonlinear_);
  if (linear_ != nullptr) SUNLinSolFree(linear_);
  if (matrix_ != nullptr) SUNMatDestroy(matrix_);
  for (N_Vector v : {id_, atol_, yp_, y_}) {
    if (v != nullptr) N_VDestroy(v);
  }
  if (context_ != nullptr) SUNContext_Free(&context_);
}

const double* Integration::y() const { return N_VGetArrayPointer(y_); }

long Integration::steps() const {
  long n = 0;
  switch (package_) {
    case Package::kCvode:
      CVodeGetNumSteps(memory_, &n);
      break;
    case Package::kArkode:
      ERKStepGetNumSteps(memory_, &n);
      break;
    case Package::kIda:
      IDAGetNumSteps(memory_, &n);
      break;
  }
  return n;
}

Integration::Outcome Integration::advance(double t_out, bool stop_at_output) {
  // max_steps bounds the whole run, the packages' SetMaxNumSteps one call: give each call the
  // rest
  const long done = steps();
  if (done >= max_steps_) return Outcome::kMaxSteps;
  const long rest = max_steps_ - done;
  stop_at_output = stop_at_output || stop_at_outputs_;
  int flag = 0;
  // the three packages number their outcomes alike: 0 success, 1 stop time, 2 root, -1 too
  // much work, other negative values failures
  switch (package_) {
    case Package::kCvode:
      CVodeSetMaxNumSteps(memory_, rest);
      if (stop_at_output) CVodeSetStopTime(memory_, t_out);
      flag = CVode(memory_, t_out, y_, &t_, CV_NORMAL);
      if (flag >= 0 && sensitivity_count_ > 0) {
        double t_sensitivity = 0;
        check_setup(CVodeGetSens(memory_, &t_sensitivity, sensitivities_), "CVodeGetSens");
      }
      static_assert(CV_ROOT_RETURN == 2 && CV_TOO_MUCH_WORK == -1);
      break;
    case Package::kArkode:
      ERKStepSetMaxNumSteps(memory_, rest);
      if (stop_at_output) ERKStepSetStopTime(memory_, t_out);
      flag = ERKStepEvolve(memory_, t_out, y_, &t_, ARK_NORMAL);
      static_assert(ARK_ROOT_RETURN == 2 && ARK_TOO_MUCH_WORK == -1);
      break;
    case Package::kIda:
      IDASetMaxNumSteps(memory_, rest);
      if (stop_at_output) IDASetStopTime(memory_, t_out);
      flag = IDASolve(memory_, t_out, &t_, y_, yp_, IDA_NORMAL);
      static_assert(IDA_ROOT_RETURN == 2 && IDA_TOO_MUCH_WORK == -1);
      break;
  }
  if (flag == 2) return Outcome::kRoot;
  if (flag >= 0) return Outcome::kReached;
  if (flag == -1 && steps() >= max_steps_) return Outcome::kMaxSteps;
  switch (package_) {
    case Package::kCvode:
      failure_ = flag_name(CVodeGetReturnFlagName(flag));
      break;
    case Package::kArkode:
      failure_ = flag_name(ERKStepGetReturnFlagName(flag));
      break;
    case Package::kIda:
      failure_ = flag_name(IDAGetReturnFlagName(flag));
      break;
  }
  if (!error_text_.empty()) failure_ += ": " + error_text_;
  return Outcome::kFailed;
}

}  // namespace bd::core::integrators
