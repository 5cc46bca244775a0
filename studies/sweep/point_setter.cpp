// The study at a sweep point from the loaded study's model (point_setter.hpp).
#include "studies/sweep/point_setter.hpp"

#include <yaml-cpp/yaml.h>

#include <cstring>
#include <string>

#include "balance/synthesis.hpp"
#include "core/fourbar/kinematics.hpp"
#include "core/input_error.hpp"
#include "studies/study/load_study_internal.hpp"
#include "studies/sweep/sweep.hpp"

namespace bd::studies::detail {

namespace {

using Field = PointSetter::Field;
using Target = PointSetter::Target;

// the target a sweep path names, when the setter knows it
std::optional<Target> target_of(const std::vector<internal::PathStep>& p) {
  auto key = [&](std::size_t i, const char* k) { return i < p.size() && p[i].key == k; };
  auto link = [&](std::size_t i) {
    for (int k = 1; k <= 3; ++k)
      if (key(i, core::link_name(k))) return k;
    return 0;
  };
  auto index = [&](std::size_t i) -> int {  // a vector element [0] or [1] at step i, last
    if (p.size() != i + 1 || !p[i].key.empty() || p[i].index > 1) return -1;
    return static_cast<int>(p[i].index);
  };
  if (key(0, "linkage")) {
    if (p.size() == 2 && key(1, "frame")) return Target{Field::kFrame};
    const int k = link(1);
    if (k == 0 || p.size() != 3) return std::nullopt;
    const std::pair<const char*, Field> fields[] = {
        {"length", Field::kLength}, {"mass", Field::kMass}, {"inertia", Field::kInertia},
        {"e", Field::kE},           {"f", Field::kF},       {"s", Field::kS},
        {"sigma", Field::kSigma}};
    for (const auto& [name, field] : fields)
      if (key(2, name)) return Target{field, k};
    return std::nullopt;
  }
  if (key(0, "loads")) {
    if (key(1, "gravity") && index(2) >= 0) return Target{Field::kGravity, 0, index(2)};
    const int k = link(1);
    if (k == 0) return std::nullopt;
    if (key(2, "force") && index(3) >= 0) return Target{Field::kForce, k, index(3)};
    if (p.size() == 3 && key(2, "moment")) return Target{Field::kMoment, k};
    return std::nullopt;
  }
  if (key(0, "scene") && p.size() == 2) {
    if (key(1, "theta1")) return Target{Field::kTheta1};
    if (key(1, "omega1")) return Target{Field::kOmega1};
    if (key(1, "duration")) return Target{Field::kDuration};
  }
  return std::nullopt;
}

core::Link& link_of(core::FourBar& m, int k) {
  return k == 1 ? m.crank : (k == 2 ? m.coupler : m.rocker);
}

bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same(const Vec2& a, const Vec2& b) { return same(a.x(), b.x()) && same(a.y(), b.y()); }
bool same(const core::Link& a, const core::Link& b) {
  return same(a.length, b.length) && same(a.mass, b.mass) && same(a.e, b.e) && same(a.f, b.f) &&
         same(a.inertia, b.inertia);
}
bool same(const core::FourBar& a, const core::FourBar& b) {
  const core::Loads &la = a.loads, &lb = b.loads;
  const core::CounterRotations &ca = a.counter_rotations, &cb = b.counter_rotations;
  return same(a.crank, b.crank) && same(a.coupler, b.coupler) && same(a.rocker, b.rocker) &&
         same(a.frame_length, b.frame_length) && a.branch == b.branch &&
         same(la.gravity, lb.gravity) && same(la.crank.force, lb.crank.force) &&
         same(la.crank.moment, lb.crank.moment) && same(la.coupler.force, lb.coupler.force) &&
         same(la.coupler.moment, lb.coupler.moment) && same(la.rocker.force, lb.rocker.force) &&
         same(la.rocker.moment, lb.rocker.moment) && same(ca.crank.inertia, cb.crank.inertia) &&
         same(ca.crank.at, cb.crank.at) && same(ca.rocker.inertia, cb.rocker.inertia) &&
         same(ca.rocker.at, cb.rocker.at);
}
bool same(const Scene& a, const Scene& b) {
  if (a.index() != b.index()) return false;
  if (const auto* d = std::get_if<core::DrivenScene>(&a)) {
    const auto& e = std::get<core::DrivenScene>(b);
    return same(d->theta1, e.theta1) && same(d->omega1, e.omega1) &&
           d->revolutions == e.revolutions && d->samples == e.samples;
  }
  const auto& f = std::get<core::FreeScene>(a);
  const auto& g = std::get<core::FreeScene>(b);
  return same(f.theta1, g.theta1) && same(f.omega1, g.omega1) && same(f.duration, g.duration) &&
         f.samples == g.samples;
}
// what a sweep row is computed from: the linkage, scene, method, tolerance and balanced design
bool same(const Study& a, const Study& b) {
  if (!same(a.fourbar(), b.fourbar()) || !same(a.scene, b.scene) || a.method != b.method ||
      !same(a.tolerance, b.tolerance) || a.balance.has_value() != b.balance.has_value()) {
    return false;
  }
  return !a.balance || (same(a.balance->model, b.balance->model) &&
                        same(a.balance->added_mass, b.balance->added_mass) &&
                        same(a.balance->added_inertia, b.balance->added_inertia));
}

}  // namespace

std::optional<PointSetter> PointSetter::make(const Study& base) {
  if (!base.sweep || !base.is_fourbar() || base.optimizes() || base.planar_balance) return {};
  if (!std::holds_alternative<core::DrivenScene>(base.scene) &&
      !std::holds_alternative<core::FreeScene>(base.scene)) {
    return {};
  }
  PointSetter setter;
  YAML::Node root;
  try {
    root = YAML::Load(base.sweep->study_text);
  } catch (const YAML::Exception&) {
    return {};
  }
  for (const SweepParameter& p : base.sweep->parameters) {
    const auto steps = internal::parse_path(p.path);
    if (!steps) return {};
    const std::optional<Target> t = target_of(*steps);
    if (!t) return {};
    // counter-rotation shafts are placed from the frame length when the file is read
    if (t->field == Field::kFrame && base.balance && base.balance->request.moment) return {};
    if (t->field == Field::kDuration && !std::holds_alternative<core::FreeScene>(base.scene)) {
      return {};
    }
    if (t->field == Field::kS || t->field == Field::kSigma) {
      // the link's s and sigma as the file states them, plain numbers (SI) only
      Polar& polar = setter.polar_[t->link - 1];
      const std::string link = std::string("linkage.") + core::link_name(t->link);
      for (const char* key : {"s", "sigma"}) {
        const auto at = internal::parse_path(link + "." + key);
        const YAML::Node n = internal::node_at(root, *at);
        double v = 0;
        if (!n.IsScalar() || !YAML::convert<double>::decode(n, v)) return {};
        (key[1] == '\0' ? polar.s : polar.sigma) = v;
      }
      polar.given = true;
    }
    setter.targets_.push_back(*t);
  }
  return setter;
}

PointSetter::Verdict PointSetter::check(const Study& base, std::span<const double> values) const {
  const std::optional<Study> mine = apply(base, values);
  std::optional<Study> loaded;
  try {
    loaded = point_study(base, values);
  } catch (const InputError&) {
  }
  if (mine && loaded) return same(*mine, *loaded) ? Verdict::kSame : Verdict::kDiffers;
  return mine || loaded ? Verdict::kDiffers : Verdict::kUndecided;
}

Study sweep_point_study(const Study& base, std::span<const double> values) {
  // this thread's setter for the sweep (kept while the same sweep runs)
  struct Cached {
    std::string text;  // the sweep's study text (compared whole: a memcmp, unlike a hash)
    std::vector<std::string> paths;
    std::optional<PointSetter> setter;
    bool checked = false;
  };
  thread_local Cached cache;
  const SweepRequest& sweep = *base.sweep;
  bool same_sweep = cache.paths.size() == sweep.parameters.size() &&
                    cache.text == sweep.study_text;
  for (std::size_t j = 0; same_sweep && j < cache.paths.size(); ++j)
    same_sweep = cache.paths[j] == sweep.parameters[j].path;
  if (!same_sweep) {
    cache = Cached{sweep.study_text, {}, PointSetter::make(base), false};
    for (const SweepParameter& p : sweep.parameters) cache.paths.push_back(p.path);
  }
  if (cache.setter && !cache.checked) {
    switch (cache.setter->check(base, values)) {
      case PointSetter::Verdict::kSame: cache.checked = true; break;
      case PointSetter::Verdict::kDiffers: cache.setter.reset(); break;
      case PointSetter::Verdict::kUndecided: break;
    }
  }
  if (cache.setter && cache.checked) {
    if (std::optional<Study> s = cache.setter->apply(base, values)) return std::move(*s);
  }
  return point_study(base, values);
}

std::optional<Study> PointSetter::apply(const Study& base, std::span<const double> values) const {
  Study s;
  s.name = base.name;
  s.source = base.source;
  s.method = base.method;
  s.tolerance = base.tolerance;
  s.scene = base.scene;
  core::FourBar model = base.fourbar();
  Polar polar[3] = {polar_[0], polar_[1], polar_[2]};
  for (std::size_t j = 0; j < targets_.size(); ++j) {
    const Target& t = targets_[j];
    const double v = values[j];
    switch (t.field) {
      case Field::kFrame: model.frame_length = v; break;
      case Field::kLength: link_of(model, t.link).length = v; break;
      case Field::kMass: link_of(model, t.link).mass = v; break;
      case Field::kInertia: link_of(model, t.link).inertia = v; break;
      case Field::kE: link_of(model, t.link).e = v; break;
      case Field::kF: link_of(model, t.link).f = v; break;
      case Field::kS: polar[t.link - 1].s = v; break;
      case Field::kSigma: polar[t.link - 1].sigma = v; break;
      case Field::kGravity: model.loads.gravity[t.index] = v; break;
      case Field::kForce:
        (t.link == 1 ? model.loads.crank : t.link == 2 ? model.loads.coupler : model.loads.rocker)
            .force[t.index] = v;
        break;
      case Field::kMoment:
        (t.link == 1 ? model.loads.crank : t.link == 2 ? model.loads.coupler : model.loads.rocker)
            .moment = v;
        break;
      case Field::kTheta1:
        if (auto* d = std::get_if<core::DrivenScene>(&s.scene)) d->theta1 = v;
        if (auto* f = std::get_if<core::FreeScene>(&s.scene)) f->theta1 = v;
        break;
      case Field::kOmega1:
        if (auto* d = std::get_if<core::DrivenScene>(&s.scene)) d->omega1 = v;
        if (auto* f = std::get_if<core::FreeScene>(&s.scene)) f->omega1 = v;
        break;
      case Field::kDuration:
        std::get<core::FreeScene>(s.scene).duration = v;  // a driven scene has none: not made
        break;
    }
  }
  // the loader's checks, in its order: any failure is left to it, for its message
  for (int k = 1; k <= 3; ++k) {
    if (!polar[k - 1].given) continue;
    if (polar[k - 1].s < 0) return std::nullopt;
    core::Link& l = link_of(model, k);
    l = core::link_from_polar(l.length, l.mass, polar[k - 1].s, polar[k - 1].sigma, l.inertia);
  }
  try {
    model = core::make_fourbar(model);
  } catch (const InputError&) {
    return std::nullopt;
  }
  if (const auto* d = std::get_if<core::DrivenScene>(&s.scene); d && d->omega1 == 0) return {};
  if (const auto* f = std::get_if<core::FreeScene>(&s.scene); f && !(f->duration > 0)) return {};
  if (!core::solve_position(model, crank_angle_at_start(s.scene))) return std::nullopt;
  if (std::holds_alternative<core::DrivenScene>(s.scene) && !core::crank_turns_fully(model)) {
    return std::nullopt;
  }
  if (base.balance) {
    try {
      s.balance = balance::balance_design(model, base.balance->request);
    } catch (const InputError&) {
      return std::nullopt;
    }
  }
  s.linkage = model;
  return s;
}

}  // namespace bd::studies::detail
