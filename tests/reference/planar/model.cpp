// Compiling a Mechanism: validation, merged mass properties, body-local attachment points.
#include "tests/reference/planar/model.hpp"

#include <algorithm>
#include <stdexcept>

namespace bd::referee {

MassProperties merged(const Body& body) {
  MassProperties out;
  out.mass = body.mass;
  Vec2 first_moment = body.mass * body.com;
  for (const auto& [m, p] : body.point_masses) {
    out.mass += m;
    first_moment += m * p;
  }
  // a massless body keeps its given reference point
  out.com = out.mass > 0 ? Vec2(first_moment / out.mass) : body.com;
  out.inertia = body.inertia + body.mass * (body.com - out.com).squaredNorm();
  for (const auto& [m, p] : body.point_masses) out.inertia += m * (p - out.com).squaredNorm();
  return out;
}

namespace detail {
namespace {

[[noreturn]] void fail(const std::string& what) { throw std::domain_error("bd::referee: " + what); }

void check_body(const Model& model, int body, bool ground_ok, const std::string& where) {
  if (body == kGround && ground_ok) return;
  if (body < 0 || body >= model.nb) fail(where + ": invalid body index " + std::to_string(body));
}

Attach attach(const Model& model, int body, const Vec2& point) {
  if (body == kGround) return {kGround, ext(point)};
  return {body, ext(point) - model.com0[body]};
}

// Characteristic length: the diagonal of the bounding box of all described points.
double characteristic_length(const Mechanism& mech) {
  std::vector<Vec2> pts;
  for (const auto& b : mech.bodies) {
    pts.push_back(b.com);
    for (const auto& pm : b.point_masses) pts.push_back(pm.second);
  }
  for (const auto& p : mech.pins) pts.push_back(p.point);
  for (const auto& s : mech.sliders) {
    pts.insert(pts.end(), {s.point, s.line_from, s.line_to});
  }
  for (const auto& g : mech.gears) pts.insert(pts.end(), {g.pivot_a, g.pivot_b, g.pitch_point});
  if (pts.empty()) return 1;
  Vec2 lo = pts[0], hi = pts[0];
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double d = (hi - lo).norm();
  return d > 0 ? d : 1;
}

void compile_bodies(const Mechanism& mech, Model& model) {
  model.nb = static_cast<int>(mech.bodies.size());
  if (model.nb == 0) fail("the mechanism has no bodies");
  for (const auto& b : mech.bodies) {
    bool ok = b.mass >= 0 && b.inertia >= 0 && std::isfinite(b.mass) && std::isfinite(b.inertia);
    for (const auto& pm : b.point_masses) ok = ok && pm.first >= 0 && std::isfinite(pm.first);
    if (!ok) fail("body '" + b.name + "': negative or non-finite mass or inertia");
    const MassProperties mp = merged(b);
    model.mass.push_back(mp.mass);
    model.inertia.push_back(mp.inertia);
    model.com0.push_back(ext(mp.com));
  }
}

void compile_pins(const Mechanism& mech, Model& model) {
  for (const auto& p : mech.pins) {
    const std::string where = "pin '" + p.name + "'";
    check_body(model, p.a, true, where);
    check_body(model, p.b, true, where);
    if (p.a == p.b) fail(where + ": a == b");
    model.pins.emplace_back(attach(model, p.a, p.point), attach(model, p.b, p.point));
    model.row_names.push_back(where + " (x)");
    model.row_names.push_back(where + " (y)");
  }
}

void compile_sliders(const Mechanism& mech, Model& model) {
  for (const auto& s : mech.sliders) {
    const std::string where = "slider '" + s.name + "'";
    check_body(model, s.point_body, true, where);
    check_body(model, s.line_body, true, where);
    if (s.point_body == s.line_body) fail(where + ": point_body == line_body");
    const Vec2 dir = s.line_to - s.line_from;
    if (!(dir.norm() > 0)) fail(where + ": line_from == line_to");
    LineRow row;
    row.p = attach(model, s.point_body, s.point);
    row.from = attach(model, s.line_body, s.line_from);
    row.line_body = s.line_body;
    row.u0 = ext(dir).normalized();
    model.lines.push_back(row);
    model.row_names.push_back(where);
  }
}

bool has_ground_pin(const Mechanism& mech, int body, const Vec2& at, double tol) {
  return std::any_of(mech.pins.begin(), mech.pins.end(), [&](const Pin& p) {
    const bool pair = (p.a == kGround && p.b == body) || (p.b == kGround && p.a == body);
    return pair && (p.point - at).norm() <= tol;
  });
}

void compile_gears(const Mechanism& mech, Model& model) {
  const double tol = 1e-9 * static_cast<double>(model.length);
  for (const auto& g : mech.gears) {
    const std::string where = "gear '" + g.name + "'";
    check_body(model, g.a, false, where);
    check_body(model, g.b, false, where);
    if (g.a == g.b) fail(where + ": a == b");
    if (!has_ground_pin(mech, g.a, g.pivot_a, tol) || !has_ground_pin(mech, g.b, g.pivot_b, tol))
      fail(where + ": each body needs a Pin to the ground at its pivot");
    GearRow row;
    row.a = g.a;
    row.b = g.b;
    row.oa = ext(g.pivot_a);
    row.ob = ext(g.pivot_b);
    row.pitch = ext(g.pitch_point);
    row.ra = (row.pitch - row.oa).norm();
    row.rb = (row.pitch - row.ob).norm();
    const Real dist = (row.ob - row.oa).norm();
    if (!(row.ra > tol && row.rb > tol) || std::abs(row.ra + row.rb - dist) > tol)
      fail(where + ": the pitch point must lie strictly between the pivots");
    row.t = perp(V2((row.ob - row.oa) / dist));
    row.pa = attach(model, g.a, g.pivot_a);
    row.pb = attach(model, g.b, g.pivot_b);
    model.gears.push_back(row);
    model.row_names.push_back(where);
  }
}

void compile_inputs(const Mechanism& mech, Model& model) {
  for (std::size_t k = 0; k < mech.inputs.size(); ++k) {
    const std::string where = "input " + std::to_string(k);
    InputRow row;
    if (const auto* a = std::get_if<AngleInput>(&mech.inputs[k])) {
      check_body(model, a->body, false, where);
      row.angle = true;
      row.body = a->body;
    } else {
      const int s = std::get<SlideInput>(mech.inputs[k]).slider;
      if (s < 0 || s >= static_cast<int>(model.lines.size())) fail(where + ": invalid slider");
      row.angle = false;
      row.slider = s;
      const auto& sl = mech.sliders[s];
      row.s0 = (ext(sl.point) - ext(sl.line_from)).dot(model.lines[s].u0);
    }
    model.inputs.push_back(row);
    model.row_names.push_back(where);
  }
  if (!mech.input_efforts.empty() && mech.input_efforts.size() != mech.inputs.size())
    fail("input_efforts must be empty or have one function per input");
}

void compile_loads(const Mechanism& mech, Model& model) {
  for (const auto& f : mech.forces) {
    check_body(model, f.body, false, "point force");
    if (!f.force) fail("point force without a function");
    model.force_points.push_back(attach(model, f.body, f.point));
  }
  for (const auto& m : mech.moments) {
    check_body(model, m.body, false, "body moment");
    if (!m.moment) fail("body moment without a function");
  }
  for (const auto& s : mech.springs) {
    check_body(model, s.a, true, "spring");
    check_body(model, s.b, true, "spring");
    if (s.a == s.b) fail("spring: a == b");
    model.springs.push_back({attach(model, s.a, s.point_a), attach(model, s.b, s.point_b)});
  }
}

}  // namespace

Model compile(const Mechanism& mech) {
  Model model;
  compile_bodies(mech, model);
  model.length = static_cast<Real>(characteristic_length(mech));
  compile_pins(mech, model);
  compile_sliders(mech, model);
  compile_gears(mech, model);
  compile_inputs(mech, model);
  compile_loads(mech, model);
  const auto rows = static_cast<Index>(model.row_names.size());
  if (rows != model.n())
    fail("3 x bodies = " + std::to_string(model.n()) + " coordinates but 2 x pins + sliders + " +
         "gears + inputs = " + std::to_string(rows) + " constraints: one input per DOF needed");
  const VecX c = residual(model, described_q(model), VecX::Zero(model.ndof()));
  for (Index i = 0; i < model.m(); ++i)
    if (std::abs(c[i]) > 1e-8 * model.length)
      fail("the described configuration violates " + model.row_names[i] + " by " +
           std::to_string(static_cast<double>(c[i])));
  return model;
}

VecX described_q(const Model& model) {
  VecX q = VecX::Zero(model.n());
  for (int i = 0; i < model.nb; ++i) q.segment<2>(3 * i) = model.com0[i];
  return q;
}

}  // namespace detail
}  // namespace bd::referee
