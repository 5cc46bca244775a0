#include "studies/study/study.hpp"

#include <algorithm>
#include <cassert>
#include <string>
#include <utility>

#include "studies/study/method.hpp"

namespace bd::studies {

const char* scene_type(const Scene& scene) { return is_free(scene) ? "free" : "driven"; }

bool is_free(const Scene& scene) {
  return std::holds_alternative<core::FreeScene>(scene) ||
         std::holds_alternative<core::planar::FreeScene>(scene);
}

double crank_angle_at_start(const Scene& scene) {
  if (const auto* f = std::get_if<core::FreeScene>(&scene)) return f->theta1;
  return std::get<core::DrivenScene>(scene).theta1;
}

const char* to_string(Method method) {
  switch (method) {
    case Method::kAuto:
      return "auto";
    case Method::kMassMatrix:
      return "mass-matrix";
    case Method::kOpenedLoop:
      return "opened-loop";
    case Method::kComplexMasses:
      return "complex-masses";
    case Method::kTruss:
      return "truss";
    case Method::kTrussDae:
      return "truss-dae";
  }
  return "auto";
}

std::optional<Method> method_named(const std::string& name) {
  for (Method m : kMethods) {
    if (name == to_string(m)) return m;
  }
  return std::nullopt;
}

std::optional<core::Formulation> formulation_of(Method method) {
  switch (method) {
    case Method::kMassMatrix:
      return core::Formulation::kMassMatrix;
    case Method::kOpenedLoop:
      return core::Formulation::kOpenedLoop;
    case Method::kComplexMasses:
      return core::Formulation::kComplexMasses;
    default:
      return std::nullopt;
  }
}

Linkage with_counterweights(const LinkageParts& parts) {
  Linkage out = parts.bare;
  if (auto* m = std::get_if<core::FourBar>(&out)) {
    for (const CounterweightPart& p : parts.counterweights) {
      core::Link& l = p.link == 1 ? m->crank : m->rocker;
      l = balance::merged(l, p.counterweight, p.link == 3);
    }
    return out;
  }
  auto& l = std::get<core::planar::Linkage>(out);
  for (const CounterweightPart& p : parts.counterweights) {
    core::planar::Link& link = l.links[static_cast<std::size_t>(p.link)];
    const Vec2 pivot = balance::planar::in_link_axes(
        l, p.link, l.nodes[static_cast<std::size_t>(p.pivot)].position);
    link = balance::planar::merged(link, p.counterweight, pivot + p.counterweight.position);
  }
  return out;
}

namespace {

// the study of another design of the same linkage type: its name, scene, method and tolerance
Study derived(const Study& study, const std::string& suffix, const Linkage& model) {
  Study d;
  d.name = study.name + suffix;
  d.linkage = model;
  d.scene = study.scene;
  d.method = study.method;
  d.tolerance = study.tolerance;
  return d;
}

// the request's variables, objective and constraints into its design problem (either type)
template <class Problem, class Request>
void set_request(Problem& p, const Request& r) {
  p.counterweights = r.counterweights;
  p.link_parameters = r.link_parameters;
  p.objective = r.objective;
  p.limits = r.limits;
  p.force_balance = r.force_balance;
  p.resolve_peaks = r.resolve_peaks;
}

}  // namespace

double linkage_size(const core::FourBar& m) {
  return std::max({m.frame_length, m.crank.length, m.coupler.length, m.rocker.length});
}

double linkage_size(const core::planar::Linkage& l) {
  double size = 0;
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    for (std::size_t j = i + 1; j < l.nodes.size(); ++j)
      size = std::max(size, (l.nodes[j].position - l.nodes[i].position).norm());
  }
  return size;
}

double linkage_size(const Study& study) {
  return study.is_fourbar() ? linkage_size(study.fourbar()) : linkage_size(study.planar());
}

Study balanced_study(const Study& study) {
  assert(study.balance.has_value());
  return derived(study, "-balanced", study.balance->model);
}

Study planar_balanced_study(const Study& study, const core::planar::Linkage& balanced) {
  return derived(study, "-balanced", core::planar::make_linkage(balanced));
}

Study optimized_study(const Study& study, const core::FourBar& design) {
  return derived(study, "-optimized", design);
}

Study planar_optimized_study(const Study& study, const core::planar::Linkage& design) {
  return derived(study, "-optimized", core::planar::make_linkage(design));
}

optimize::planar::DesignProblem planar_design_problem(const Study& study) {
  assert(study.planar_optimize.has_value() && !study.is_fourbar());
  const PlanarOptimizeRequest& r = *study.planar_optimize;
  optimize::planar::DesignProblem p;
  p.original = study.planar();
  if (const auto* free = std::get_if<core::planar::FreeScene>(&study.scene)) {
    p.scene = *free;
  } else {
    p.scene = std::get<core::planar::DrivenScene>(study.scene);
  }
  p.simulate.tolerance = study.tolerance;
  set_request(p, r);
  return p;
}

optimize::DesignProblem design_problem(const Study& study) {
  assert(study.optimize.has_value() && study.is_fourbar());
  const OptimizeRequest& r = *study.optimize;
  optimize::DesignProblem p;
  p.original = study.fourbar();
  p.scene = std::holds_alternative<core::FreeScene>(study.scene)
                ? decltype(p.scene)(std::get<core::FreeScene>(study.scene))
                : decltype(p.scene)(std::get<core::DrivenScene>(study.scene));
  const MethodChoice method = choose_method(study);
  p.formulation = method.formulation;
  p.tolerance = study.tolerance;
  set_request(p, r);
  return p;
}

}  // namespace bd::studies
