#include "studies/study/optimize_request.hpp"

#include <cstdio>

#include "balance/planar.hpp"
#include "core/number_text.hpp"

namespace bd::studies {

namespace {

// a link's inertia about the point p (link axes, from its first joint) [kg m^2]
double inertia_about(const core::Link& l, const Vec2& p) {
  return l.inertia + l.mass * (Vec2(l.e, l.f) - p).squaredNorm();
}

}  // namespace

const char* to_string(optimize::LinkParameterVariable::Parameter p) {
  using P = optimize::LinkParameterVariable::Parameter;
  switch (p) {
    case P::kMass:
      return "mass";
    case P::kE:
      return "e";
    case P::kF:
      return "f";
    case P::kInertia:
      return "inertia";
  }
  return "?";
}

double added_mass(const core::FourBar& original, const core::FourBar& design) {
  double sum = 0;
  for (int k = 1; k <= 3; ++k) sum += core::link(design, k).mass - core::link(original, k).mass;
  return sum;
}

double added_inertia(const core::FourBar& original, const core::FourBar& design) {
  // pivots in link axes: crank A0 and coupler A1 (first joints), rocker A3 (its second joint)
  const Vec2 pivots[] = {Vec2(0, 0), Vec2(0, 0), Vec2(original.rocker.length, 0)};
  double sum = 0;
  for (int k = 1; k <= 3; ++k) {
    sum += inertia_about(core::link(design, k), pivots[k - 1]) -
           inertia_about(core::link(original, k), pivots[k - 1]);
  }
  sum += design.counter_rotations.crank.inertia - original.counter_rotations.crank.inertia;
  sum += design.counter_rotations.rocker.inertia - original.counter_rotations.rocker.inertia;
  return sum;
}

double metric_value(const core::Metrics& m, optimize::Metric metric, double added) {
  return metric == optimize::Metric::kAddedMass ? added : optimize::value(m, metric);
}

std::string objective_text(const OptimizeRequest& request) {
  std::string text;
  for (const optimize::Term& t : request.objective) {
    if (!text.empty()) text += " + ";
    text += text::digits(t.weight, 6) + " x " + optimize::to_string(t.metric);
  }
  return text + " (each / original)";
}

std::string constraints_text(const OptimizeRequest& request) {
  std::string text;
  auto add = [&](const std::string& s) { text += (text.empty() ? "" : "; ") + s; };
  if (request.force_balance) add("full force balance (eq. 57)");
  for (const optimize::Limit& l : request.limits) {
    if (l.metric == optimize::Metric::kAddedMass) {
      add("added_mass <= " + text::digits(l.value, 6) + " kg");
    } else {
      add(std::string(optimize::to_string(l.metric)) + " <= " + text::digits(l.value, 6) +
          " x original");
    }
  }
  return text.empty() ? "none" : text;
}

std::string objective_text(const PlanarOptimizeRequest& request) {
  std::string text;
  for (const optimize::planar::Term& t : request.objective) {
    if (!text.empty()) text += " + ";
    text += text::digits(t.weight, 6) + " x " + t.metric;
  }
  return text + " (each / original)";
}

std::string constraints_text(const PlanarOptimizeRequest& request) {
  std::string text;
  auto add = [&](const std::string& s) { text += (text.empty() ? "" : "; ") + s; };
  if (request.force_balance) add("full force balance");
  for (const optimize::planar::Limit& l : request.limits) {
    if (l.metric == "added_mass") {
      add("added_mass <= " + text::digits(l.value, 6) + " kg");
    } else {
      add(l.metric + " <= " + text::digits(l.value, 6) + " x original");
    }
  }
  return text.empty() ? "none" : text;
}

double added_inertia(const core::planar::Linkage& original, const core::planar::Linkage& design) {
  namespace bp = balance::planar;
  double sum = 0;
  for (std::size_t k = 0; k < original.links.size() && k < design.links.size(); ++k) {
    const int link = static_cast<int>(k);
    const int pivot = bp::counterweight_pivot(original, link);
    const Vec2 p =
        bp::in_link_axes(original, link, original.nodes[static_cast<std::size_t>(pivot)].position);
    auto about = [&](const core::planar::Link& l) {
      return l.inertia + l.mass * (Vec2(l.e, l.f) - p).squaredNorm();
    };
    sum += about(design.links[k]) - about(original.links[k]);
  }
  for (const core::planar::BalanceShaft& s : design.shafts) {
    bool had = false;
    for (const core::planar::BalanceShaft& o : original.shafts) had = had || o.name == s.name;
    if (!had) sum += s.inertia + s.mass * s.eccentricity.squaredNorm();
  }
  return sum;
}

}  // namespace bd::studies
