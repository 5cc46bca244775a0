#pragma once
/// The SUNDIALS integrators of free motion behind one door (core/simulation.hpp `Integrator`):
/// CVODE (Adams-Moulton, BDF; from the CVODES library, which adds forward sensitivities with
/// respect to parameters), ARKODE ERKStep (embedded explicit Runge-Kutta pairs) for an ODE
/// y' = f(t, y), and IDA for a DAE F(t, y, y') = 0. Used by core/fourbar/simulate.cpp (the
/// four-bar's reduced equation in theta1) and core/fourbar/opened_loop_dae.cpp (its opened loop's
/// ODE and DAE). Internal to core: SUNDIALS types appear in no public header.
///
/// One Integration owns every SUNDIALS object of one run (context, vectors, matrix, solvers,
/// integrator memory) and frees them in reverse order of creation; it captures the integrator's
/// error text instead of letting SUNDIALS print it (core never prints); and it advances to each
/// output instant with the same outcomes whatever the package, so the callers' output loops are
/// written once.
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>
#include <sundials/sundials_nvector.h>

#include <string>
#include <vector>

#include "core/simulation.hpp"

namespace bd::core::integrators {

/// y' = f(t, y) as CVODE and ARKODE call it: 0 on success; > 0 a recoverable failure (CVODE
/// retries with a smaller step; ERKStep in SUNDIALS 6.4 cannot and stops); < 0 stops the run.
using RhsFn = int (*)(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data);
/// g(t, y): the run stops where a component changes sign (root finding; CVODE and ERKStep).
using RootFn = int (*)(sunrealtype t, N_Vector y, sunrealtype* g, void* user_data);
/// CVODE's projection onto a constraint manifold (CVodeSetProjFn; BDF only).
using ProjectionFn = int (*)(sunrealtype t, N_Vector y, N_Vector correction, sunrealtype eps,
                             N_Vector error, void* user_data);
/// F(t, y, y') of a DAE as IDA calls it; return values as RhsFn.
using ResidualFn = int (*)(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, void* user_data);

/// What to integrate from t0 and how.
struct Problem {
  Integrator integrator = Integrator::kCvodeAdams;
  std::vector<double> y0;                  // state at t0
  std::vector<double> absolute_tolerance;  // per component, as y0
  double tolerance = 1e-10;                // relative, all components
  /// [s] the start: a restart of a run at one of its instants (a planar free run's peak search,
  /// core/planar/simulate.hpp) integrates in the run's own time, which its loads depend on
  double t0{};
  double t_end{};                          // the run never steps past it [s]
  long max_steps = 1000000;                // steps over the whole run
  void* user_data{};                       // passed to every callback
  RhsFn rhs{};                             // ODE integrators (all but kIda)
  RootFn root{};                           // optional, one function (not with kIda)
  ProjectionFn projection{};               // optional, kCvodeBdf only
  /// ERK pairs only: steps of this fixed size [s] without error control (0: adaptive). For
  /// order checks (tests/core/integrators_test.cpp); simulate_free never sets it.
  double fixed_step{};
  // kIda only
  ResidualFn residual{};
  std::vector<double> yp0;         // y'(t0), consistent with y0 (F(t0, y0, yp0) = 0)
  std::vector<bool> differential;  // false: algebraic, excluded from the error test
  double initial_step{};           // [s]; 0: IDA's own estimate
  /// kCvodeAdams and kCvodeBdf only: CVODES' forward sensitivities s_i = dy/dp_i of the state
  /// with respect to the parameters p[which[i]], none when `which` is empty. The right-hand side
  /// reads every parameter from `parameters` (through user_data) at each call: CVODES perturbs
  /// them there to form its centred difference quotients of (df/dy) s_i + df/dp_i (one
  /// directional difference, two right-hand sides per sensitivity), so no Jacobian is written
  /// by hand. The sensitivities start at `initial` (0 where it is empty: y0 does not depend on
  /// p; a run continued from an instant of another starts at that instant's) and take part in
  /// the error test at their own relative `tolerance` and the state's smallest absolute
  /// tolerance divided by their scale.
  struct Sensitivities {
    double* parameters{};        // every parameter the right-hand side reads
    std::vector<int> which;      // the entries differentiated
    std::vector<double> scales;  // their typical magnitudes (CVODES' pbar), > 0, as `which`
    double tolerance = 1e-7;     // relative, of the sensitivities' error test
    /// s_i(t0), one per entry of `which`, each of y0's size; or empty
    std::vector<std::vector<double>> initial;
  } sensitivities;
};

/// An integration in progress. Not copyable or movable (SUNDIALS keeps pointers into it).
class Integration {
 public:
  /// Sets the integrator up at t = t0.
  /// @throws std::runtime_error naming the SUNDIALS call if the setup fails (with a problem that
  ///         core builds, only by running out of memory).
  explicit Integration(const Problem& problem);
  ~Integration();
  Integration(const Integration&) = delete;
  Integration& operator=(const Integration&) = delete;

  enum class Outcome {
    kReached,   // t() == t_out; y() is the solution there
    kRoot,      // the root function changed sign at t() < t_out; y() is the solution there
    kMaxSteps,  // the run's max_steps are used up; t(), y() where it stopped
    kFailed,    // the integrator gave up (failure() says why); t(), y() where it stopped
  };
  /// Advances to t_out (> t(), <= t_end). The solution at t_out comes from the integrator's
  /// dense output (CVODE's Nordsieck array, ARKODE's Hermite interpolant, IDA's BDF
  /// polynomial: the interpolant CVodeGetDky, ERKStepGetDky and IDAGetDky evaluate), unless
  /// `stop_at_output` or stops_at_outputs(), which end a step exactly at t_out.
  Outcome advance(double t_out, bool stop_at_output = false);
  /// True for the ERK pairs of order 6 and 8, whose steps always end at the output instants:
  /// ARKODE's Hermite interpolant has degree at most 5 and needs the right-hand side at interior
  /// points; between the long steps of these methods it is far less accurate than the steps
  /// (by orders of magnitude on the paper example, docs/performance.md), and costs four
  /// right-hand sides per output.
  bool stops_at_outputs() const { return stop_at_outputs_; }

  double t() const { return t_; }  // time reached [s]
  const double* y() const;         // the state at t()
  long steps() const;              // steps taken so far
  /// The sensitivity dy/dp_i at t() (Problem::sensitivities, its i-th parameter), after an
  /// advance() that reached t_out or a root.
  const double* sensitivity(int i) const;
  /// After kFailed: the integrator's flag name and its last error message, e.g.
  /// "CV_CONV_FAILURE: CVode: At t = 1.2 and h = 1e-15, the corrector convergence failed ...".
  const std::string& failure() const { return failure_; }

 private:
  enum class Package { kCvode, kArkode, kIda };
  // the constructor's steps for each package, after the context, y_ and atol_
  void set_up_cvode(const Problem& p);
  void set_up_arkode(const Problem& p);
  void set_up_ida(const Problem& p);
  // the dense matrix and linear solver of BDF and IDA's Newton iterations
  void set_up_dense_solver(const Problem& p);
  // CVODES' forward sensitivities (after set_up_cvode)
  void set_up_sensitivities(const Problem& p);

  Package package_;
  bool stop_at_outputs_;
  long max_steps_;
  double t_{};
  std::string error_text_;  // the integrator's last error message (its error handler)
  std::string failure_;
  // the SUNDIALS objects; members left null are not used by this integrator
  SUNContext context_{};
  N_Vector y_{}, yp_{}, atol_{}, id_{};
  N_Vector* sensitivities_{};  // CVODES' s_i, Problem::sensitivities.which.size() of them
  int sensitivity_count_{};
  std::vector<double> parameter_scales_;  // CVODES keeps the pointers
  std::vector<int> parameter_list_;
  SUNNonlinearSolver sensitivity_nonlinear_{};
  SUNMatrix matrix_{};
  SUNLinearSolver linear_{};
  SUNNonlinearSolver nonlinear_{};
  void* memory_{};
};

}  // namespace bd::core::integrators
