#include "core/planar/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/number_text.hpp"
#include "core/planar/blocks.hpp"
#include "core/planar/system.hpp"
#include "core/polar_angle.hpp"

namespace bd::core::planar {

using detail::GradientEntry;
using detail::NodeVectors;
using detail::System;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Newton stops when a step moves no coordinate by more than this fraction of the length scale:
// the position is then exact to round-off (the previous step was ~1e-8 of the scale or less)
constexpr double kNewtonStep = 1e-14;
constexpr int kNewtonIterations = 40;
// a constraint residual below this fraction of the length scale is round-off of the closure
// equations (lengths and coordinates of that size): Newton stops there when its steps stagnate
constexpr double kRoundOffResidual = 16 * std::numeric_limits<double>::epsilon();
// a last Newton step below this (times the linkage's size) leaves the Jacobian unchanged to
// round-off: its factorisation is kept
constexpr double kRefactorStep = 4 * std::numeric_limits<double>::epsilon();
// the chord method (solve_position): each step must shrink the last at least by this factor, the
// first step must stay within this fraction of the linkage's size, and it takes at most this many
constexpr double kChordContraction = 0.25;
constexpr double kChordReach = 1e-2;
constexpr int kChordIterations = 12;
// A factorisation whose reciprocal condition estimate is below this is a singular position:
// velocities and forces there would lose more than half of their digits.
constexpr double kSingularRcond = 1e-8;
// A converged position whose reciprocal condition estimate is below this is a singular position
// too. At a singular position hit to round-off (a driven sample landing on a dead centre) the
// root is double and Newton ends within ~sqrt(round-off) of it: the estimate there is ~1e-8, not
// 0, and the rates, which grow like 1/sqrt of the distance to the singular position, come out at
// 1e8 times their size (a piston driven onto its dead centre gave a drive force of 1e30 N).
// 1e-6 calls singular what lies within ~1e-12 (relative) of one.
constexpr double kSingularSolution = 1e-6;
// Newton's guard: a factorisation whose smallest pivot is below this fraction of its largest is
// checked by the condition estimate (far cheaper than estimating it at every iteration)
constexpr double kSingularPivot = 1e-4;
// pivots within this ratio of each other leave the condition estimate far above kSingularSolution
// (the rows have gradients of unit length and the systems are small)
constexpr double kWellConditionedPivot = 1e-2;

// x rounded to the nearest whole number, ties to even (std::round's ties away from zero would
// differ only at a jump of exactly half a turn, which continued angles exclude); |x| < 2^51.
// std::round is a library call on the baseline x86-64 this is built for.
double nearest_whole(double x) {
  constexpr double kRound = 6755399441055744.0;  // 1.5·2^52
  return (x + kRound) - kRound;
}

}  // namespace

std::string detail::inputs_text(const Model& model, const std::vector<double>& inputs) {
  std::string s;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const Input& in = model.linkage().inputs[k];
    s += (k ? ", " : "") + in.name + " = " + text::digits(inputs[k], 10) +
         (in.kind == Input::Kind::kAngle ? " rad" : " m");
  }
  return s;
}

namespace {

using detail::inputs_text;

// the name of row `row`, for messages
std::string row_name(const System& s, int row) {
  const System::RowRef& ref = s.row_ref[static_cast<std::size_t>(row)];
  const Linkage& l = s.linkage;
  switch (ref.kind) {
    case System::RowRef::Kind::kElement:
      return "the length of link " + l.links[static_cast<std::size_t>(ref.index)].name;
    case System::RowRef::Kind::kRigid: {
      const System::RigidRows& r = s.rigid[static_cast<std::size_t>(ref.index)];
      return "node " + l.nodes[static_cast<std::size_t>(r.node)].name + " on link " +
             l.links[static_cast<std::size_t>(r.link)].name;
    }
    case System::RowRef::Kind::kSlider: {
      const Slider& sl = l.sliders[static_cast<std::size_t>(ref.index)];
      return "slider " + sl.name + " (node " + l.nodes[static_cast<std::size_t>(sl.node)].name +
             " on its guide)";
    }
    case System::RowRef::Kind::kInput:
      return "input " + l.inputs[static_cast<std::size_t>(ref.index)].name;
  }
  return "?";
}

void resize(Instant& in, const Model& m) {
  const Linkage& l = m.linkage();
  in.x.assign(l.nodes.size(), Vec2(0, 0));
  in.v.assign(l.nodes.size(), Vec2(0, 0));
  in.a.assign(l.nodes.size(), Vec2(0, 0));
  for (std::size_t i = 0; i < l.nodes.size(); ++i) in.x[i] = l.nodes[i].position;
  in.input.assign(l.inputs.size(), 0.0);
  in.input_rate.assign(l.inputs.size(), 0.0);
  in.input_acceleration.assign(l.inputs.size(), 0.0);
  in.effort.assign(l.inputs.size(), 0.0);
  in.angle.assign(l.links.size(), 0.0);
  in.omega.assign(l.links.size(), 0.0);
  in.alpha.assign(l.links.size(), 0.0);
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const Vec2 d = l.nodes[static_cast<std::size_t>(l.links[k].nodes[1])].position -
                   l.nodes[static_cast<std::size_t>(l.links[k].nodes[0])].position;
    in.angle[k] = std::atan2(d.y(), d.x());
  }
  in.slide.assign(l.sliders.size(), 0.0);
  in.slide_rate.assign(l.sliders.size(), 0.0);
  in.slide_acceleration.assign(l.sliders.size(), 0.0);
  in.ground_reaction.assign(m.ground_nodes().size(), Vec2(0, 0));
  in.guide_reaction.assign(m.frame_guides().size(), Vec2(0, 0));
  in.joint_force.assign(m.joints().size(), Vec2(0, 0));
  in.guide_force.assign(m.link_guides().size(), Vec2(0, 0));
  in.shaft_reaction.assign(l.shafts.size(), Vec2(0, 0));
  in.spring_reaction.assign(m.frame_springs().size(), Vec2(0, 0));
  in.drive_reaction.assign(m.frame_drives().size(), Vec2(0, 0));
}

bool finite(const VectorXd& v) { return v.allFinite(); }

// dst = src; for the usual equal sizes a plain copy (operator= of a vector of one or two values
// costs several times the copy)
void copy_values(const std::vector<double>& src, std::vector<double>& dst) {
  if (dst.size() == src.size()) {
    std::copy(src.begin(), src.end(), dst.begin());
  } else {
    dst = src;
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// model

Model::Model(const Linkage& linkage) : system_(std::make_unique<System>(make_linkage(linkage))) {
  const Linkage& l = system_->linkage;
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    if (l.nodes[i].ground) ground_nodes_.push_back(static_cast<int>(i));
  }
  for (std::size_t k = 0; k < l.sliders.size(); ++k) {
    (l.sliders[k].link < 0 ? frame_guides_ : link_guides_).push_back(static_cast<int>(k));
  }
  for (std::size_t k = 0; k < l.springs.size(); ++k) {
    const Spring& sp = l.springs[k];
    if (l.nodes[static_cast<std::size_t>(sp.a)].ground ||
        l.nodes[static_cast<std::size_t>(sp.b)].ground)
      frame_springs_.push_back(static_cast<int>(k));
  }
  for (std::size_t k = 0; k < l.inputs.size(); ++k) {
    const Input& in = l.inputs[k];
    if (in.kind == Input::Kind::kSlide && l.sliders[static_cast<std::size_t>(in.slider)].link < 0)
      frame_drives_.push_back(static_cast<int>(k));
  }
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    if (l.nodes[i].ground) continue;
    std::vector<int> links;
    for (std::size_t k = 0; k < l.links.size(); ++k) {
      const auto& n = l.links[k].nodes;
      if (std::find(n.begin(), n.end(), static_cast<int>(i)) != n.end()) {
        links.push_back(static_cast<int>(k));
      }
    }
    const int node = static_cast<int>(i);
    const bool carries = std::any_of(l.sliders.begin(), l.sliders.end(),
                                     [&](const Slider& s) { return s.node == node; }) ||
                         std::any_of(l.point_masses.begin(), l.point_masses.end(),
                                     [&](const PointMass& p) { return p.node == node; });
    if (links.size() == 2) {
      joints_.push_back({l.nodes[i].name, node, links[1]});
    } else if (links.size() > 2) {
      for (std::size_t j = 1; j < links.size(); ++j) {
        joints_.push_back({l.nodes[i].name + "_" + l.links[static_cast<std::size_t>(links[j])].name,
                           node, links[j]});
      }
    } else if (links.size() == 1 && carries) {
      joints_.push_back({l.nodes[i].name, node, links[0]});
    }
  }
  for (const JointForce& j : joints_) {
    joint_slots_.push_back(system_->slot_of[static_cast<std::size_t>(j.link) * l.nodes.size() +
                                            static_cast<std::size_t>(j.node)]);
  }
  for (const System::ElementRow& e : system_->elements)
    length_scale_ = std::max(length_scale_, e.length);
}

Model::~Model() = default;
Model::Model(const Model& other)
    : system_(std::make_unique<System>(*other.system_)),
      ground_nodes_(other.ground_nodes_),
      frame_guides_(other.frame_guides_),
      link_guides_(other.link_guides_),
      frame_springs_(other.frame_springs_),
      frame_drives_(other.frame_drives_),
      joints_(other.joints_),
      joint_slots_(other.joint_slots_),
      length_scale_(other.length_scale_) {}
Model& Model::operator=(const Model& other) {
  if (this != &other) *this = Model(other);
  return *this;
}

const Linkage& Model::linkage() const { return system_->linkage; }
void Model::set_mass_parameters(const double* pi) { detail::set_mass_parameters(*system_, pi); }
int Model::coordinates() const { return system_->n; }
int Model::inputs() const { return static_cast<int>(system_->inputs.size()); }

Workspace::Workspace(const Model& model) {
  const System& s = model.system();
  resize(instant, model);
  q.setZero(s.n);
  qd.setZero(s.n);
  qdd.setZero(s.n);
  g.setZero(s.rows);
  gamma.setZero(s.rows);
  F.setZero(s.n);
  rhs.setZero(s.n);
  lambda.setZero(s.rows);
  G.setZero(s.rows, s.n);
  T.setZero(s.n, model.inputs());
  MT.setZero(s.n, model.inputs());
  reduced.setZero(model.inputs(), model.inputs());
  ldlt = Eigen::LDLT<MatrixXd>(std::max(model.inputs(), 1));
  step.setZero(s.n);
  c.setZero(s.n);
  right.setZero(model.inputs());
  zdd.setZero(model.inputs());
  target.assign(static_cast<std::size_t>(model.inputs()), Vec2(0, 0));
  on_link.assign(static_cast<std::size_t>(s.slots), Vec2(0, 0));
  element_force.assign(model.linkage().links.size(), Vec4::Zero());
}

std::vector<double> drawn_inputs(const Model& model) {
  const System& s = model.system();
  NodeVectors x;
  for (const Node& n : s.linkage.nodes) x.push_back(n.position);
  std::vector<double> z;
  for (const System::InputRow& in : s.inputs) {
    if (in.angle) {
      const Vec2 d = x[static_cast<std::size_t>(in.q)] - x[static_cast<std::size_t>(in.p)];
      z.push_back(std::atan2(d.y(), d.x()));
    } else {
      z.push_back(detail::slide_position(s, s.sliders[static_cast<std::size_t>(in.slider)], x));
    }
  }
  return z;
}

Expected<bool, PlanarError> check_drawn(const Model& model) {
  const System& s = model.system();
  NodeVectors x;
  for (const Node& n : s.linkage.nodes) x.push_back(n.position);
  VectorXd g;
  detail::constraint_values(s, x, {}, g);
  if (g.size() == 0) return true;
  Eigen::Index worst = 0;
  const double misfit = g.cwiseAbs().maxCoeff(&worst);
  if (misfit <= 1e-9 * model.length_scale()) return true;
  return Unexpected<PlanarError>(
      PlanarError{PlanarError::Kind::kAssembly, "the drawn positions do not close " +
                                                    row_name(s, static_cast<int>(worst)) +
                                                    ": off by " + text::digits(misfit, 3) + " m"});
}

int mobility(const Model& model) {
  const System& s = model.system();
  NodeVectors x;
  for (const Node& n : s.linkage.nodes) x.push_back(n.position);
  MatrixXd G;
  detail::constraint_jacobian(s, x, s.structural_rows, G);
  if (s.n == 0) return 0;
  Eigen::FullPivLU<MatrixXd> lu(G);
  lu.setThreshold(1e-10);
  return s.n - static_cast<int>(lu.rank());
}

// ---------------------------------------------------------------------------------------------
// positions

namespace {

Unexpected<PlanarError> singular_at(const Model& model, const std::vector<double>& inputs) {
  return Unexpected<PlanarError>(
      PlanarError{PlanarError::Kind::kSingular,
                  "singular position at " + inputs_text(model, inputs) +
                      " (the inputs do not fix the linkage's position there: a dead centre or a "
                      "limit position)"});
}

// The chord method from ws.instant.x (the guess): Newton's steps with the factorisation of the
// last solved position, whose Jacobian differs from the one here by about the distance moved (a
// driven or integrated sample's step). Each iteration costs a constraint evaluation and two
// triangular solves instead of a Jacobian and a factorisation. It converges linearly; a
// contraction worse than kChordContraction, or too many steps, hands over to Newton. On success
// the position is exact to round-off: after the step that moves no coordinate by more than the
// step limit, one more (the remaining error shrinks by the contraction again), unless the
// contraction of the last two steps puts that one below round-off. The angle inputs'
// rows are taken as u × d (detail::AngleRow::kCross: no atan2 per iteration), which the first
// step's reach keeps near their root, where they and the angle form agree.
bool chord_iterations(const Model& model, Workspace& ws) {
  const System& s = model.system();
  Instant& in = ws.instant;
  const double step_limit = kNewtonStep * model.length_scale();
  double previous = std::numeric_limits<double>::infinity();
  bool converged = false;
  for (int it = 0; it < kChordIterations; ++it) {
    detail::constraint_values(s, in.x, ws.target, ws.g, detail::AngleRow::kCross);
    ws.lu.solve(ws.g, ws.step);
    const double size = ws.step.cwiseAbs().maxCoeff();
    if (!std::isfinite(size) || (it == 0 && size > kChordReach * model.length_scale()) ||
        (size > kChordContraction * previous && size > kRefactorStep * model.length_scale()))
      return false;  // (below kRefactorStep the steps are round-off and need not shrink)
    ws.q -= ws.step;
    detail::nodes_from_q(s, ws.q, in.x);
    if (converged) return true;
    converged = size <= step_limit;
    // the next step, as the last two shrank, would move no coordinate by more than round-off:
    // it is not taken
    if (converged && it > 0 && size * (size / previous) <= kRefactorStep * model.length_scale())
      return true;
    previous = size;
  }
  return false;
}

}  // namespace

Expected<bool, PlanarError> solve_position(const Model& model, Workspace& ws,
                                           const std::vector<Vec2>& guess,
                                           const std::vector<double>& inputs, PositionRoute route) {
  const System& s = model.system();
  Instant& in = ws.instant;
  // the closed forms block by block where the plan has them and the guess tells each block's
  // branch; anything they decline (a dead centre near) is decided by the general route below
  if (route == PositionRoute::kLeanest && detail::prime_closed_blocks(model, ws, guess) &&
      detail::place_by_blocks(model, ws, guess, inputs) == detail::Placement::kPlaced)
    return true;
  ws.by_blocks = false;
  if (s.rows != s.n) {
    return Unexpected<PlanarError>(
        PlanarError{PlanarError::Kind::kMobility, std::to_string(s.inputs.size()) + " inputs for " +
                                                      std::to_string(s.n - s.structural_rows) +
                                                      " free coordinates left by the constraints"});
  }
  if (s.n == 0) {
    in.x = guess;
    copy_values(inputs, in.input);
    return true;
  }
  detail::input_targets(s, inputs, ws.target);
  // the final factorisation, at the solution: the rates, accelerations and multipliers use it
  auto solved = [&]() -> Expected<bool, PlanarError> {
    detail::constraint_jacobian(s, in.x, s.rows, ws.G);
    ws.lu.compute(ws.G);
    ws.factorised = false;
    // a factorisation with well-sized pivots is well conditioned; estimate only the others
    if (!ws.G.allFinite() ||
        (!(ws.lu.pivot_ratio() >= kWellConditionedPivot) && !(ws.lu.rcond() >= kSingularSolution)))
      return singular_at(model, inputs);
    ws.factorised = true;
    copy_values(inputs, in.input);
    return true;
  };
  if (ws.factorised) {
    in.x = guess;
    detail::q_from_nodes(s, in.x, ws.q);
    if (chord_iterations(model, ws)) return solved();
  }
  ws.factorised = false;
  in.x = guess;
  detail::q_from_nodes(s, in.x, ws.q);
  const double step_limit = kNewtonStep * model.length_scale();
  // the residual at round-off: below it Newton cannot improve the position further
  const double round_off = kRoundOffResidual * model.length_scale();
  double previous_step = std::numeric_limits<double>::infinity();
  for (int it = 0; it < kNewtonIterations; ++it) {
    detail::constraint_values(s, in.x, ws.target, ws.g);
    detail::constraint_jacobian(s, in.x, s.rows, ws.G);
    if (!finite(ws.g) || !ws.G.allFinite()) {
      return Unexpected<PlanarError>(PlanarError{
          PlanarError::Kind::kNonFinite, "non-finite constraint at " + inputs_text(model, inputs)});
    }
    ws.lu.compute(ws.G);
    // inside the iterations a cheap guard (the smallest pivot against the largest; the rows
    // have gradients of unit length), the condition estimate only where it is poor
    if (!(ws.lu.pivot_ratio() >= kSingularPivot) && !(ws.lu.rcond() >= kSingularRcond)) {
      // a singular Jacobian at a closed position is a singular position; away from closure it
      // means Newton cannot go on
      Eigen::Index worst = 0;
      const double residual = s.rows > 0 ? ws.g.cwiseAbs().maxCoeff(&worst) : 0.0;
      if (residual <= 1e-9 * model.length_scale()) return singular_at(model, inputs);
      return Unexpected<PlanarError>(
          PlanarError{PlanarError::Kind::kAssembly,
                      "the linkage cannot be assembled at " + inputs_text(model, inputs) + ": " +
                          row_name(s, static_cast<int>(worst)) + " does not close"});
    }
    ws.lu.solve(ws.g, ws.step);
    ws.q -= ws.step;
    detail::nodes_from_q(s, ws.q, in.x);
    const double last_step = ws.step.cwiseAbs().maxCoeff();
    // near a singular position (a dead centre a hair's breadth away) the step at round-off is
    // the condition number times round-off, above step_limit: where the residual the step was
    // solved from was at round-off and the step no longer halves, the position is as exact as
    // the constraints can say
    const bool stagnant = last_step > step_limit && last_step > 0.5 * previous_step &&
                          ws.g.cwiseAbs().maxCoeff() <= round_off;
    previous_step = last_step;
    if (stagnant) return solved();
    if (last_step <= step_limit) {
      // the rates and accelerations need the factorisation at the solution, not at the iterate
      // before it (up to step_limit away: a relative error of 1e-14 in every rate, which an
      // integrator at tight tolerance sees as noise)
      if (last_step > kRefactorStep * model.length_scale()) return solved();
      if (!(ws.lu.pivot_ratio() >= kWellConditionedPivot) && !(ws.lu.rcond() >= kSingularSolution))
        return singular_at(model, inputs);
      ws.factorised = true;
      copy_values(inputs, in.input);
      return true;
    }
  }
  detail::constraint_values(s, in.x, ws.target, ws.g);
  Eigen::Index worst = 0;
  if (s.rows > 0) ws.g.cwiseAbs().maxCoeff(&worst);
  return Unexpected<PlanarError>(
      PlanarError{PlanarError::Kind::kAssembly,
                  "the linkage cannot be assembled at " + inputs_text(model, inputs) + ": " +
                      row_name(s, static_cast<int>(worst)) +
                      " does not close (no position found near the previous one)"});
}

Expected<bool, PlanarError> assemble(const Model& model, Workspace& ws,
                                     const std::vector<double>& inputs) {
  const std::vector<double> from = drawn_inputs(model);
  // steps of at most 0.05 rad, or 2 % of the length scale for a slide, so that Newton stays on
  // the drawn branch
  double steps = 1;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const bool angle = model.linkage().inputs[k].kind == Input::Kind::kAngle;
    const double unit = angle ? 0.05 : 0.02 * model.length_scale();
    steps = std::max(steps, std::ceil(std::abs(inputs[k] - from[k]) / unit));
  }
  std::vector<Vec2> guess;
  for (const Node& n : model.linkage().nodes) guess.push_back(n.position);
  const std::vector<Vec2> drawn = guess;
  std::vector<double> z(inputs.size());
  for (int i = 1; i <= static_cast<int>(steps); ++i) {
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      z[k] = from[k] + (inputs[k] - from[k]) * (i / steps);
    }
    if (auto ok = solve_position(model, ws, guess, z, PositionRoute::kGeneral); !ok) {
      // a drawing on a singular position of the inputs (a slider-crank drawn at a dead centre,
      // driven from the piston) is where they do not fix the position: the way from it cannot
      // be followed, whatever the start; say so rather than where the first step failed
      if (i == 1 && ok.error().kind != PlanarError::Kind::kNonFinite) {
        if (auto at_drawing = solve_position(model, ws, drawn, from, PositionRoute::kGeneral);
            !at_drawing && at_drawing.error().kind == PlanarError::Kind::kSingular) {
          return Unexpected<PlanarError>(PlanarError{
              PlanarError::Kind::kSingular,
              "the linkage cannot be moved from its drawing (" + inputs_text(model, from) +
                  ") to " + inputs_text(model, inputs) +
                  ": the drawing is a dead centre of the inputs (they do not fix the linkage's "
                  "position there); draw the linkage away from it"});
        }
      }
      return ok;
    }
    guess = ws.instant.x;
  }
  if (steps < 1) return solve_position(model, ws, guess, inputs, PositionRoute::kGeneral);
  return true;
}

void efforts_at(const Model& model, double t, std::vector<double>& out) {
  const std::vector<Input>& inputs = model.linkage().inputs;
  out.resize(inputs.size());
  for (std::size_t k = 0; k < inputs.size(); ++k) out[k] = inputs[k].effort(t);
}

std::vector<double> efforts_at(const Model& model, double t) {
  std::vector<double> e;
  efforts_at(model, t, e);
  return e;
}

// ---------------------------------------------------------------------------------------------
// velocities, accelerations and forces

namespace {

// out = M x for the n x n column-major m, by columns; N = n at compile time (unrolled) or 0
template <int N>
void multiply_columns(const double* m, const double* x, double* out, int n_run) {
  const int n = N > 0 ? N : n_run;
  for (int i = 0; i < n; ++i) out[i] = m[i] * x[0];
  for (int j = 1; j < n; ++j) {
    const double xj = x[j];
    for (int i = 0; i < n; ++i) out[i] += m[i + n * j] * xj;
  }
}

// y = M x for the small square M (Eigen's general product costs several times the products
// themselves at these sizes); the sizes of the usual linkages (2 to 8 coordinates) unrolled
void multiply(const MatrixXd& M, const VectorXd& x, VectorXd& y) {
  const int n = static_cast<int>(M.rows());
  y.resize(n);
  if (n == 0) return;
  const double* m = M.data();
  switch (n) {
    case 2: return multiply_columns<2>(m, x.data(), y.data(), n);
    case 4: return multiply_columns<4>(m, x.data(), y.data(), n);
    case 6: return multiply_columns<6>(m, x.data(), y.data(), n);
    case 8: return multiply_columns<8>(m, x.data(), y.data(), n);
    default: return multiply_columns<0>(m, x.data(), y.data(), n);
  }
}

// x = G⁻¹ b with the factorisation of the last position: the whole system's (ws.lu) or the
// blocks' (core/planar/blocks.hpp)
void solve_constraints(const Model& model, Workspace& ws, const VectorXd& b, VectorXd& x) {
  if (ws.by_blocks) {
    detail::block_solve(model, ws, b, x);
  } else {
    ws.lu.solve(b, x);
  }
}

// the node velocities for the inputs' rates, with the factorisation at the current position
void velocities(const Model& model, Workspace& ws, const std::vector<double>& rates) {
  const System& s = model.system();
  ws.rhs.setZero(s.n);
  for (const System::InputRow& in : s.inputs) {
    const double r = rates[static_cast<std::size_t>(in.input)];
    ws.rhs[in.row] = in.angle ? in.length * r : r;
  }
  solve_constraints(model, ws, ws.rhs, ws.qd);
  detail::node_rates_from(s, ws.qd, ws.instant.v);
  copy_values(rates, ws.instant.input_rate);
}

// One pass over the links, each read once (the same nodes serve all three): its angle, rate and
// acceleration; its element's nodal forces, inertia less applied load (eq. 46), at its first and
// second node into ws.element_force (what M q̈ - F assembles, multiplier_rhs(), and what the
// joint forces start from, link_node_forces()); and its mass's part of the shaking force and
// moment, inertial (-m a and its moment about the origin, -I α) and static (its weight and
// moment). The parts are started here; shaking_rest() adds the other masses and the loads.
void link_pass(const Model& model, Workspace& ws) {
  const System& s = model.system();
  const Linkage& l = s.linkage;
  Instant& in = ws.instant;
  const Vec2 g = l.loads.gravity;
  Vec2 f_inertial(0, 0), f_static(0, 0);
  double m_inertial = 0.0, m_static = 0.0;
  for (std::size_t k = 0; k < s.elements.size(); ++k) {
    const System::ElementRow& e = s.elements[k];
    const std::size_t p = static_cast<std::size_t>(e.p), q = static_cast<std::size_t>(e.q);
    const Vec2 &xp = in.x[p], &xq = in.x[q], &ap = in.a[p], &aq = in.a[q];
    const Vec2 d = xq - xp, dv = in.v[q] - in.v[p], da = aq - ap;
    const double n2 = d.squaredNorm();
    // a link an input turns is at the input's angle (exactly where the blocks placed it; to
    // round-off of the position solve otherwise)
    const int input = s.link_input[k];
    const double angle =
        input >= 0 ? in.input[static_cast<std::size_t>(input)] : polar_angle(d.y(), d.x());
    in.angle[k] = angle + 2 * kPi * nearest_whole((in.angle[k] - angle) / (2 * kPi));
    const double omega = cross(d, dv) / n2;
    const double alpha = (cross(d, da) - 2 * d.dot(dv) * omega) / n2;
    in.omega[k] = omega;
    in.alpha[k] = alpha;

    Vec4 acc;
    acc << ap, aq;
    Vec4& f = ws.element_force[k];
    f.noalias() = s.element_M[k] * acc;
    const double moment =
        s.shafts.empty() ? s.link_moment[k] : detail::link_moment_at(s, static_cast<int>(k), in.x);
    if (!s.link_force[k].isZero(0.0) || moment != 0.0) {  // a loaded link
      f -= element_nodal_forces(s.com_weights[k], s.link_force[k], moment, xp, xq);
    }

    const PointWeights& w = s.com_weights[k];
    const double m = l.links[k].mass;
    const Vec2 c = w.at_p * xp + w.at_q * xq;
    const Vec2 ma = m * (w.at_p * ap + w.at_q * aq);
    f_inertial -= ma;
    m_inertial -= cross(c, ma) + l.links[k].inertia * alpha;
    f_static += m * g;
    m_static += m * cross(c, g);
  }
  in.Fsh_inertial = f_inertial;
  in.Msh_inertial = m_inertial;
  in.Fsh_static = f_static;
  in.Msh_static = m_static;
}

// the sliders' positions, rates and accelerations, from the nodes
void slider_kinematics(const Model& model, Instant& in) {
  const System& s = model.system();
  for (std::size_t k = 0; k < s.sliders.size(); ++k) {
    const System::SliderRow& sl = s.sliders[k];
    in.slide[k] = detail::slide_position(s, sl, in.x);
    in.slide_rate[k] = detail::slide_rate(s, sl, in.x, in.v);
    const std::size_t P = static_cast<std::size_t>(sl.node);
    if (!sl.on_link) {
      in.slide_acceleration[k] = sl.unit.dot(in.a[P]);
    } else {
      const std::size_t Q = static_cast<std::size_t>(sl.from_node),
                        R = static_cast<std::size_t>(sl.to_node);
      const Vec2 a = in.x[P] - in.x[Q], b = in.x[R] - in.x[Q];
      const Vec2 ad = in.v[P] - in.v[Q], bd = in.v[R] - in.v[Q];
      const Vec2 aa = in.a[P] - in.a[Q], ba = in.a[R] - in.a[Q];
      in.slide_acceleration[k] = (aa.dot(b) + 2 * ad.dot(bd) + a.dot(ba)) / sl.length;
    }
  }
}

// M q̈ - F (the efforts excluded) into ws.rhs, the right-hand side of the multipliers'
// Gᵀ λ = M q̈ - F: the element forces (each link's inertia less its loads, link_pass()),
// the point masses' inertia, less the rest of the applied forces (node forces, point masses'
// weights, springs)
void multiplier_rhs(const Model& model, Workspace& ws) {
  const System& s = model.system();
  const Instant& in = ws.instant;
  const Linkage& l = s.linkage;
  if (l.loads.node_forces.empty() && l.point_masses.empty() && l.springs.empty()) {
    ws.rhs.setZero(s.n);  // no applied force beyond the links' (in their element forces)
  } else {
    detail::applied_forces(s, in.x, in.v, nullptr, ws.F, false);
    ws.rhs = -ws.F;
  }
  double* rhs = ws.rhs.data();
  auto add = [&](int node, const Vec2& f) {
    const int c = s.coord[static_cast<std::size_t>(node)];
    if (c < 0) return;
    rhs[c] += f.x();
    rhs[c + 1] += f.y();
  };
  const std::size_t links = s.elements.size();
  for (std::size_t k = 0; k < links; ++k) {
    add(s.elements[k].p, ws.element_force[k].segment<2>(0));
    add(s.elements[k].q, ws.element_force[k].segment<2>(2));
  }
  for (const PointMass& pm : s.linkage.point_masses)
    add(pm.node, pm.mass * in.a[static_cast<std::size_t>(pm.node)]);
}

// per joint slot (System::slots): the force on the link from the joint there (f = inertia -
// load - the link's own constraint forces), from the element forces and the multipliers of the
// structural rows (ws.lambda), into ws.on_link
void link_node_forces(const Model& model, Workspace& ws) {
  const System& s = model.system();
  const Instant& in = ws.instant;
  const std::size_t nodes = s.linkage.nodes.size();
  Vec2* on_link = ws.on_link.data();
  const std::size_t links = s.elements.size();
  for (std::size_t k = 0; k < links; ++k) {
    const System::ElementRow& e = s.elements[k];
    const Vec2& xp = in.x[static_cast<std::size_t>(e.p)];
    const Vec2& xq = in.x[static_cast<std::size_t>(e.q)];
    // the element's own row (row k): its axial force λ_k along the unit vector p -> q,
    // row_gradient()'s element case without its dispatch
    const Vec2 axial = ws.lambda[static_cast<Eigen::Index>(k)] * ((xq - xp) / e.length);
    const Vec4& ef = ws.element_force[k];
    // the link's slots: the element's first node, its second, then its other nodes (each slot
    // is one link's, so the element starts them)
    Vec2* f = on_link + s.first_slot[k];
    f[0] = ef.segment<2>(0) + axial;
    f[1] = ef.segment<2>(2) - axial;
    for (int j = s.first_slot[k] + 2; j < s.first_slot[k + 1]; ++j) on_link[j] = Vec2(0, 0);
  }
  GradientEntry entries[3];
  for (int row = static_cast<int>(links); row < s.rows; ++row) {
    const System::RowRef& ref = s.row_ref[static_cast<std::size_t>(row)];
    if (ref.kind == System::RowRef::Kind::kInput) {  // an angle input's row, without dispatch
      const System::InputRow& ir = s.inputs[static_cast<std::size_t>(ref.index)];
      if (ir.angle) {
        const Vec2 force = ws.lambda[row] * detail::angle_input_gradient(ir, in.x);
        const std::size_t link =
            static_cast<std::size_t>(s.linkage.inputs[static_cast<std::size_t>(ir.input)].link);
        on_link[s.slot_of[link * nodes + static_cast<std::size_t>(ir.q)]] -= force;
        on_link[s.slot_of[link * nodes + static_cast<std::size_t>(ir.p)]] += force;
        continue;
      }
    }
    const int count = detail::row_gradient(s, in.x, row, entries);
    for (int j = 0; j < count; ++j) {
      if (entries[j].link < 0) continue;
      const std::size_t at = static_cast<std::size_t>(entries[j].link) * nodes +
                             static_cast<std::size_t>(entries[j].node);
      on_link[s.slot_of[at]] -= ws.lambda[row] * entries[j].grad;
    }
  }
}

// the balance shafts' forces on the frame: each shaft's bearing carries its weight and inertia
// and the reaction of its tooth force, whose action on the link goes to the frame through the
// link's pivot (its moment about the pivot is the drive's torque on the link, already in the
// multipliers); a drive without a pitch point reacts on the frame with (ratio - 1) τ instead
template <class OnFrame>
void shaft_forces(const Model& model, Instant& in, OnFrame& on_frame) {
  const System& s = model.system();
  const Linkage& l = s.linkage;
  for (std::size_t k = 0; k < l.shafts.size(); ++k) {
    const BalanceShaft& b = l.shafts[k];
    const System::ShaftRef& r = s.shafts[k];
    const std::size_t link = static_cast<std::size_t>(b.link);
    const detail::ShaftMotion m =
        detail::shaft_motion(s, static_cast<int>(k), in.x, in.omega[link], in.alpha[link]);
    Vec2 reaction = b.mass * (l.loads.gravity - m.a);
    if (r.mesh) {
      const Vec2 tooth = r.per_torque * m.torque * r.normal;  // on the link
      const auto g = std::find(model.ground_nodes().begin(), model.ground_nodes().end(), r.pivot);
      in.ground_reaction[static_cast<std::size_t>(g - model.ground_nodes().begin())] += tooth;
      on_frame(tooth, l.nodes[static_cast<std::size_t>(r.pivot)].position);
      reaction -= tooth;
    } else {
      in.Msh += (b.ratio - 1) * m.torque;
    }
    in.shaft_reaction[k] = reaction;
    on_frame(reaction, b.at);
  }
}

// the forces on the frame: ground pins, guides, slide drives on frame guides, springs anchored
// to it; the shaking force and moment; the joint forces
void frame_forces(const Model& model, Workspace& ws) {
  const System& s = model.system();
  const Linkage& l = s.linkage;
  Instant& in = ws.instant;
  const Vec2* on_link = ws.on_link.data();
  in.Fsh = Vec2(0, 0);
  in.Msh = 0.0;
  auto on_frame = [&](const Vec2& force, const Vec2& at) {
    in.Fsh += force;
    in.Msh += cross(at, force);
  };
  for (std::size_t i = 0; i < model.ground_nodes().size(); ++i) {
    const int g = model.ground_nodes()[i];
    Vec2 r(0, 0);
    for (int j = s.ground_first[i]; j < s.ground_first[i + 1]; ++j) r -= on_link[s.ground_slots[j]];
    in.ground_reaction[i] = r;
    on_frame(r, in.x[static_cast<std::size_t>(g)]);
  }
  for (std::size_t i = 0; i < model.frame_guides().size(); ++i) {
    const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(model.frame_guides()[i])];
    in.guide_reaction[i] = -ws.lambda[sl.row] * sl.normal;
    on_frame(in.guide_reaction[i], in.x[static_cast<std::size_t>(sl.node)]);
  }
  std::size_t drive = 0;
  for (const System::InputRow& ir : s.inputs) {
    const double e = in.effort[static_cast<std::size_t>(ir.input)];
    if (ir.angle) {
      in.Msh -= e;  // the drive's stator reacts on the frame
    } else {
      const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(ir.slider)];
      if (!sl.on_link) {
        in.drive_reaction[drive++] = -e * sl.unit;
        on_frame(-e * sl.unit, in.x[static_cast<std::size_t>(sl.node)]);
      }
    }
  }
  for (std::size_t j = 0; j < model.frame_springs().size(); ++j) {
    const int k = model.frame_springs()[j];
    const Spring& sp = l.springs[static_cast<std::size_t>(k)];
    const detail::SpringState st = detail::spring_state(s, k, in.x, in.v);
    const bool at_a = l.nodes[static_cast<std::size_t>(sp.a)].ground;
    in.spring_reaction[j] = (at_a ? st.tension : -st.tension) * st.unit;
    on_frame(in.spring_reaction[j], in.x[static_cast<std::size_t>(at_a ? sp.a : sp.b)]);
  }
  const std::vector<int>& joint_slots = model.joint_slots();
  for (std::size_t j = 0; j < joint_slots.size(); ++j) in.joint_force[j] = on_link[joint_slots[j]];
  // a slider on a moving guide: the rows' forces on its node, λ ∂g/∂x_node (detail::row_gradient:
  // the normal row -perp(b)/L, a slide input's b/L, b the guide from its first node to its
  // second), reacted by the guide's link
  for (std::size_t j = 0; j < model.link_guides().size(); ++j) {
    const int k = model.link_guides()[j];
    const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(k)];
    const Vec2 b = (in.x[static_cast<std::size_t>(sl.to_node)] -
                    in.x[static_cast<std::size_t>(sl.from_node)]) /
                   sl.length;
    Vec2 on_node = ws.lambda[sl.row] * -perp(b);
    for (const System::InputRow& ir : s.inputs) {
      if (!ir.angle && ir.slider == k) on_node += ws.lambda[ir.row] * b;
    }
    in.guide_force[j] = -on_node;
  }
  shaft_forces(model, in, on_frame);
}

// the shaking force's and moment's parts from the masses other than the links' (point masses,
// balance shafts) and the applied loads, added to link_pass()'s: the inertial part -Σ m a and
// -dH/dt about the origin, the static part the weights and the applied loads with their moments
// about the origin
void shaking_rest(const Model& model, Instant& in) {
  const System& s = model.system();
  const Linkage& l = s.linkage;
  const Vec2 g = l.loads.gravity;
  // a mass m at c with acceleration a
  auto mass_at = [&](double m, const Vec2& c, const Vec2& a) {
    in.Fsh_inertial -= m * a;
    in.Msh_inertial -= cross(c, m * a);
    in.Fsh_static += m * g;
    in.Msh_static += cross(c, m * g);
  };
  for (const PointMass& pm : l.point_masses) {
    const std::size_t n = static_cast<std::size_t>(pm.node);
    mass_at(pm.mass, in.x[n], in.a[n]);
  }
  for (std::size_t k = 0; k < l.shafts.size(); ++k) {
    const BalanceShaft& b = l.shafts[k];
    const std::size_t link = static_cast<std::size_t>(b.link);
    const detail::ShaftMotion m =
        detail::shaft_motion(s, static_cast<int>(k), in.x, in.omega[link], in.alpha[link]);
    mass_at(b.mass, b.at + m.r, m.a);
    in.Msh_inertial -= b.inertia * m.alpha;
  }
  for (const LinkLoad& load : l.loads.link_loads) {
    const System::ElementRow& e = s.elements[static_cast<std::size_t>(load.link)];
    const PointWeights& w = s.com_weights[static_cast<std::size_t>(load.link)];
    const Vec2 c = w.at_p * in.x[static_cast<std::size_t>(e.p)] +
                   w.at_q * in.x[static_cast<std::size_t>(e.q)];
    in.Fsh_static += load.force;
    in.Msh_static += cross(c, load.force) + load.moment;
  }
  for (const NodeForce& f : l.loads.node_forces) {
    in.Fsh_static += f.force;
    in.Msh_static += cross(in.x[static_cast<std::size_t>(f.node)], f.force);
  }
}

// every force output from the element forces, the multipliers of the structural rows
// (ws.lambda) and the efforts
void forces(const Model& model, Workspace& ws) {
  slider_kinematics(model, ws.instant);
  link_node_forces(model, ws);
  frame_forces(model, ws);
  shaking_rest(model, ws.instant);
}

// after the accelerations q̈: the multipliers from Gᵀ λ = M q̈ - F (efforts of the inputs
// excluded from F: they are the input rows' multipliers) and every output; the nodes'
// accelerations from q̈ unless `accelerations_set` (the closed forms set both)
Expected<bool, PlanarError> finish(const Model& model, Workspace& ws, double t,
                                   bool accelerations_set = false) {
  const System& s = model.system();
  Instant& in = ws.instant;
  in.t = t;
  if (!accelerations_set) detail::node_rates_from(s, ws.qdd, in.a);
  link_pass(model, ws);
  multiplier_rhs(model, ws);
  // Gᵀ λ = rhs
  if (ws.by_blocks) {
    detail::block_solve_transpose(model, ws, ws.rhs, ws.lambda);
  } else {
    ws.lambda = ws.rhs;
    ws.lu.solve_transpose(ws.lambda);
  }
  for (const System::InputRow& ir : s.inputs) {
    in.effort[static_cast<std::size_t>(ir.input)] =
        ir.angle ? ws.lambda[ir.row] * ir.length : ws.lambda[ir.row];
  }
  forces(model, ws);
  // (accelerations set by the closed forms that are not finite make the multipliers so: the
  // right-hand side M a - F carries them, 0 * NaN included)
  // (a sum is finite where its terms are: NaN and infinities carry through it; only finite
  // terms near the largest double could overflow it, no result of a linkage)
  if (!std::isfinite(ws.lambda.sum()) || (!accelerations_set && !finite(ws.qdd))) {
    return Unexpected<PlanarError>(PlanarError{
        PlanarError::Kind::kNonFinite, "non-finite result at " + inputs_text(model, in.input)});
  }
  return true;
}

}  // namespace

void detail::finish_outputs(const Model& model, Workspace& ws) {
  link_pass(model, ws);
  forces(model, ws);
}

Expected<bool, PlanarError> inverse_dynamics(const Model& model, Workspace& ws, double t,
                                             const std::vector<double>& rates,
                                             const std::vector<double>& accelerations) {
  const System& s = model.system();
  if (ws.by_blocks && s.blocks.closed) {
    detail::closed_form_kinematics(model, ws, rates, accelerations);
    return finish(model, ws, t, true);
  }
  velocities(model, ws, rates);
  detail::constraint_bias(s, ws.instant.x, ws.instant.v, s.rows, ws.gamma);
  ws.rhs = -ws.gamma;
  for (const System::InputRow& in : s.inputs) {
    const double z = accelerations[static_cast<std::size_t>(in.input)];
    ws.rhs[in.row] += in.angle ? in.length * z : z;
  }
  solve_constraints(model, ws, ws.rhs, ws.qdd);
  copy_values(accelerations, ws.instant.input_acceleration);
  return finish(model, ws, t);
}

Expected<bool, PlanarError> forward_dynamics(const Model& model, Workspace& ws, double t,
                                             const std::vector<double>& rates,
                                             const std::vector<double>& efforts) {
  const System& s = model.system();
  const int dof = model.inputs();
  velocities(model, ws, rates);
  // q̇ = T ż: T's columns solve G T = E (E the input rows, scaled as the rows are)
  ws.MT.setZero(s.n, dof);  // the input rows' unit columns, scaled as the rows are
  for (const System::InputRow& in : s.inputs) ws.MT(in.row, in.input) = in.angle ? in.length : 1.0;
  if (ws.by_blocks) {
    ws.T.resize(s.n, dof);
    for (int k = 0; k < dof; ++k) {
      ws.rhs = ws.MT.col(k);  // (ws.rhs is written whole below)
      detail::block_solve(model, ws, ws.rhs, ws.step);
      ws.T.col(k) = ws.step;
    }
  } else {
    ws.lu.solve(ws.MT, ws.T);
  }
  // q̈ = T z̈ + c with G c = -γ
  detail::constraint_bias(s, ws.instant.x, ws.instant.v, s.rows, ws.gamma);
  solve_constraints(model, ws, ws.gamma, ws.c);  // c = -G⁻¹ γ, the sign applied below
  detail::applied_forces(s, ws.instant.x, ws.instant.v, nullptr, ws.F);
  ws.MT.noalias() = s.M * ws.T;
  ws.reduced.noalias() = ws.T.transpose() * ws.MT;
  multiply(s.M, ws.c, ws.rhs);
  ws.rhs += ws.F;  // F - M c with c = -G⁻¹ γ
  ws.right.noalias() = ws.T.transpose() * ws.rhs;
  for (int k = 0; k < dof; ++k) ws.right[k] += efforts[static_cast<std::size_t>(k)];
  auto singular = [&]() {
    return Unexpected<PlanarError>(PlanarError{PlanarError::Kind::kSingular,
                                               "the reduced inertia of the inputs is singular at " +
                                                   inputs_text(model, ws.instant.input)});
  };
  if (dof == 1) {  // a scalar: what the factorisation below does for one input, without it
    const double m = ws.reduced(0, 0);
    if (!(m != 0) || !std::isfinite(m)) return singular();
    ws.zdd.resize(1);
    ws.zdd[0] = ws.right[0] / m;
  } else {
    ws.ldlt.compute(ws.reduced);
    if (ws.ldlt.info() != Eigen::Success || !(ws.ldlt.rcond() > 1e-14)) return singular();
    ws.zdd.noalias() = ws.ldlt.solve(ws.right);
  }
  ws.qdd.noalias() = ws.T * ws.zdd;
  ws.qdd -= ws.c;
  ws.instant.input_acceleration.assign(ws.zdd.data(), ws.zdd.data() + dof);
  auto done = finish(model, ws, t);
  // the efforts are given: the input rows' multipliers reproduce them to round-off
  ws.instant.effort = efforts;
  return done;
}

}  // namespace bd::core::planar
