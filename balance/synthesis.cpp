#include "balance/synthesis.hpp"

namespace bd::balance {

Vec2 crank_shaft(const BalanceRequest& request, const core::FourBar& model) {
  return request.crank_at ? *request.crank_at : Vec2(0.0, -model.crank.length);
}

Vec2 rocker_shaft(const BalanceRequest& request, const core::FourBar& model) {
  return request.rocker_at ? *request.rocker_at : Vec2(model.frame_length, -model.rocker.length);
}

const char* to_string(CounterweightShape shape) {
  return shape == CounterweightShape::kDisc ? "disc" : "point";
}

BalancedDesign balance_design(const core::FourBar& model, const BalanceRequest& request) {
  using Step = SynthesisError::Step;
  BalancedDesign design;
  design.request = request;
  design.model = model;
  if (request.moment && !request.force) {
    throw SynthesisError(Step::kMoment,
                         "a full moment balance needs a full force balance first (force: full)");
  }

  // counterweights on crank and rocker (eq. 57)
  if (request.force) {
    // built in place (assigning into a default-constructed one trips GCC 12's
    // -Wmaybe-uninitialized on the std::optional members)
    const ForceBalancedDesign fb = [&] {
      try {
        return force_balance(model, request.crank_counterweight,
                                      request.rocker_counterweight);
      } catch (const InputError& e) {
        throw SynthesisError(Step::kForce, e.what());
      }
    }();
    design.model = fb.model;
    design.crank_counterweight = fb.crank;
    design.rocker_counterweight = fb.rocker;
    design.added_mass = fb.added_mass;
    design.added_inertia = fb.added_inertia;
  }

  // counter-rotations equal to Berkof's reduced inertias
  if (request.moment) {
    const double before =
        model.counter_rotations.crank.inertia + model.counter_rotations.rocker.inertia;
    const MomentBalancedDesign mb = [&] {
      try {
        return moment_balance(design.model, crank_shaft(request, model),
                                       rocker_shaft(request, model));
      } catch (const InputError& e) {
        throw SynthesisError(Step::kMoment, e.what());
      }
    }();
    design.model = mb.model;
    design.added_inertia += mb.crank_inertia + mb.rocker_inertia - before;
  }

  // the design must be a valid model in its own right (it is written out as a study)
  try {
    design.model = core::make_fourbar(design.model);
  } catch (const InputError& e) {
    throw SynthesisError(request.moment ? Step::kMoment : Step::kForce,
                         std::string("the balanced design is not a valid linkage: ") + e.what());
  }
  design.conditions = check_balance(design.model);
  return design;
}

}  // namespace bd::balance
