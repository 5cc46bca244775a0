#pragma once
/// Balanced-design synthesis: what to balance and how (a study's `balance:` section,
/// docs/study-format.md "balance"), and the design made from it by force_balance(),
/// moment_balance() and check_balance(), with what was added.
#include <optional>
#include <string>

#include "balance/conditions.hpp"
#include "balance/counter_rotation.hpp"
#include "balance/counterweight.hpp"
#include "core/fourbar/model.hpp"
#include "core/input_error.hpp"
#include "core/types.hpp"

namespace bd::balance {

/// The study file's `balance:` section, defaults in place.
struct BalanceRequest {
  bool force = true;    // full shaking-force balance by counterweights on crank and rocker
  bool moment = false;  // full shaking-moment balance by counter-rotations (needs force and a
                        // Berkof coupler)
  CounterweightSpec crank_counterweight;   // default: a point mass at distance l1
  CounterweightSpec rocker_counterweight;  // default: a point mass at distance l3
  std::optional<Vec2> crank_at;            // crank counter-rotation shaft [m]; default (0, -l1)
  std::optional<Vec2> rocker_at;           // rocker counter-rotation shaft [m]; default (l4, -l3)
};

/// The shaft positions a request uses [m]: as given, else crank (0, -l1) and rocker (l4, -l3).
Vec2 crank_shaft(const BalanceRequest& request, const core::FourBar& model);
Vec2 rocker_shaft(const BalanceRequest& request, const core::FourBar& model);

/// A synthesised design: the original with its counterweights merged into the crank and the
/// rocker and, for a moment balance, counter-rotations; with what was added and how well the
/// balance conditions hold.
struct BalancedDesign {
  BalanceRequest request;
  core::FourBar model;  // the balanced design, checked by core::make_fourbar()
  std::optional<Counterweight> crank_counterweight;   // empty: none added
  std::optional<Counterweight> rocker_counterweight;  // empty: none added
  /// Σ counterweight masses [kg] (counter-rotation discs are described by their inertia only)
  double added_mass{};
  /// Σ counterweight inertias about their pivots plus the counter-rotation inertias J added [kg
  /// m^2]
  double added_inertia{};
  BalanceReport conditions;  // check_balance of `model`
};

/// Why a synthesis failed, and at which step (so a study file can point at the key that asked).
class SynthesisError : public InputError {
 public:
  enum class Step { kForce, kMoment };
  SynthesisError(Step step, const std::string& message) : InputError(message), step_(step) {}
  Step step() const { return step_; }

 private:
  Step step_;
};

/// Synthesises the design the request asks for: force_balance with the counterweight
/// specs (when request.force), then moment_balance at the shaft positions (when
/// request.moment), then check_balance. With force and moment both off the design is
/// the original.
/// @throws SynthesisError (step kForce or kMoment, the balance layer's message) if a spec is
///         invalid, if moment is asked without force, or if the linkage cannot be moment balanced
///         (its coupler is not a Berkof coupler).
BalancedDesign balance_design(const core::FourBar& model, const BalanceRequest& request);

/// "point" or "disc".
const char* to_string(CounterweightShape shape);

}  // namespace bd::balance
