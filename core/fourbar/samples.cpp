#include "core/fourbar/samples.hpp"

#include <algorithm>
#include <numbers>

namespace bd::core::samples {

FourBar with_paper_loads(FourBar m, const Vec2& gravity) {
  // eq. 56
  m.loads.crank = {Vec2(1.1, 1.2), 0.37};
  m.loads.coupler = {Vec2(1.3, -1.4), 0.28};
  m.loads.rocker = {Vec2(1.5, 1.6), 0.19};
  m.loads.gravity = gravity;
  return make_fourbar(m);
}

FourBar paper_fourbar() { return with_paper_loads(paper_fourbar_unloaded()); }

FourBar paper_fourbar_unloaded() {
  // eq. 56
  FourBar m;
  m.crank = link_from_polar(1.0, 2.1, 0.6, 0.3, 1.1);
  m.coupler = link_from_polar(3.0, 3.0, 1.45, 0.4, 3.1);
  m.rocker = link_from_polar(2.0, 2.2, 1.66, -0.4, 2.1);
  m.frame_length = 3.2;
  m.branch = Branch::kPlus;
  return make_fourbar(m);
}

FourBar parallelogram() {
  // l1 = l3 = 1, l2 = l4 = 3; on branch +1 it is the parallelogram for theta1 in (0, pi)
  FourBar m;
  m.crank = {1.0, 1.0, 0.4, 0.1, 0.05};
  m.coupler = {3.0, 2.0, 1.2, -0.2, 1.2};
  m.rocker = {1.0, 1.5, 0.3, 0.2, 0.08};
  m.frame_length = 3.0;
  m.branch = Branch::kPlus;
  return make_fourbar(m);
}

FourBar double_crank() {
  FourBar m;
  m.crank = {2.5, 2.0, 1.0, 0.2, 0.9};
  m.coupler = {3.0, 3.0, 1.4, -0.3, 2.5};
  m.rocker = {2.8, 2.5, 1.2, 0.1, 1.7};
  m.frame_length = 1.0;
  m.branch = Branch::kPlus;
  return make_fourbar(m);
}

FourBar triple_rocker() {
  FourBar m;
  m.crank = {2.0, 1.0, 0.8, 0.1, 0.4};
  m.coupler = {2.0, 1.5, 1.0, 0.0, 0.6};
  m.rocker = {2.0, 1.2, 0.9, -0.1, 0.5};
  m.frame_length = 3.5;
  m.branch = Branch::kPlus;
  return make_fourbar(m);
}

FourBar folding_rocker() {
  // |A1A3| in [1.5, 3.5] against [|l2 - l3|, l2 + l3] = [1.8, 4.2]
  FourBar m;
  m.crank = {1.0, 1.5, 0.4, 0.1, 0.2};
  m.coupler = {3.0, 2.5, 1.4, 0.2, 2.0};
  m.rocker = {1.2, 1.2, 0.5, -0.1, 0.15};
  m.frame_length = 2.5;
  m.branch = Branch::kPlus;
  return make_fourbar(m);
}

FourBar random_crank_rocker(std::mt19937_64& rng) {
  auto uniform = [&rng](double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(rng);
  };
  FourBar m;
  // Grashof with the crank shortest and a margin of 0.2 m, so the transmission angle stays
  // away from 0 and pi over the whole turn
  for (;;) {
    const double l1 = uniform(0.2, 1.0), l2 = uniform(l1 + 0.3, 3.5), l3 = uniform(l1 + 0.3, 3.5),
                 l4 = uniform(l1 + 0.3, 3.5);
    const double longest = std::max({l2, l3, l4});
    if (l1 + longest + 0.2 < l2 + l3 + l4 - longest) {
      m.crank.length = l1;
      m.coupler.length = l2;
      m.rocker.length = l3;
      m.frame_length = l4;
      break;
    }
  }
  for (Link* l : {&m.crank, &m.coupler, &m.rocker}) {
    l->mass = uniform(0.5, 5.0);
    l->e = uniform(-0.5, 1.5) * l->length;
    l->f = uniform(-0.5, 0.5) * l->length;
    l->inertia = uniform(0.01, 2.0);
  }
  for (LinkLoad* load : {&m.loads.crank, &m.loads.coupler, &m.loads.rocker}) {
    load->force = Vec2(uniform(-5, 5), uniform(-5, 5));
    load->moment = uniform(-2, 2);
  }
  m.loads.gravity = Vec2(uniform(-10, 10), uniform(-10, 10));
  m.branch = uniform(0, 1) < 0.5 ? Branch::kPlus : Branch::kMinus;
  return make_fourbar(m);
}

}  // namespace bd::core::samples
