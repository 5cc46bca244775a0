#include "balance/planar.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <set>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "core/planar/model.hpp"

namespace bd::balance::planar {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// a link's nodes, element length and drawn direction
struct LinkFrame {
  int p{}, q{};
  double length{};
  double angle{};  // of the first-to-second node line as drawn [rad]
};
LinkFrame frame_of(const cp::Linkage& l, int k) {
  const cp::Link& link = l.links[static_cast<std::size_t>(k)];
  LinkFrame f;
  f.p = link.nodes[0];
  f.q = link.nodes[1];
  const Vec2 d = l.nodes[static_cast<std::size_t>(f.q)].position -
                 l.nodes[static_cast<std::size_t>(f.p)].position;
  f.length = d.norm();
  f.angle = std::atan2(d.y(), d.x());
  return f;
}

// a residual that cancels to round-off against the sum of its terms' sizes
bool cancels(const VectorXd& residual, double terms) {
  return residual.norm() <= 1e-10 * std::max(terms, 1e-300);
}

double rms_of_pairs(const VectorXd& v) {  // v = (x0, y0, x1, y1, ...): RMS of the magnitudes
  const Eigen::Index n = v.size() / 2;
  return n > 0 ? std::sqrt(v.squaredNorm() / static_cast<double>(n)) : 0.0;
}

}  // namespace

Vec2 in_link_axes(const cp::Linkage& l, int k, const Vec2& point) {
  const LinkFrame f = frame_of(l, k);
  const Vec2 d = point - l.nodes[static_cast<std::size_t>(f.p)].position;
  const double c = std::cos(f.angle), s = std::sin(f.angle);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

int counterweight_pivot(const cp::Linkage& l, int link) {
  const int g = cp::pivot_of(l, link);
  return g >= 0 ? g : l.links[static_cast<std::size_t>(link)].nodes[0];
}

Eigen::VectorXd Parameters::of(const cp::Linkage& l) {
  const std::vector<double> pi = cp::mass_parameters(l);
  return Eigen::Map<const VectorXd>(pi.data(), static_cast<Eigen::Index>(pi.size()));
}

std::vector<ComplexMass> equivalent_masses(const cp::Linkage& l) {
  std::vector<ComplexMass> mu(l.nodes.size(), ComplexMass(0, 0));
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const cp::Link& link = l.links[k];
    const LinkFrame f = frame_of(l, static_cast<int>(k));
    const ComplexMass s_over_l = ComplexMass(link.e, link.f) / f.length;
    mu[static_cast<std::size_t>(f.p)] += link.mass * (1.0 - s_over_l);
    mu[static_cast<std::size_t>(f.q)] += link.mass * s_over_l;
  }
  for (const cp::PointMass& pm : l.point_masses) mu[static_cast<std::size_t>(pm.node)] += pm.mass;
  return mu;
}

Expected<Kinematics, cp::PlanarError> kinematics(
    const cp::Model& model, const std::vector<std::vector<double>>& values,
    const std::vector<std::vector<double>>& rates,
    const std::vector<std::vector<double>>& accelerations) {
  const cp::Linkage& l = model.linkage();
  const std::size_t dof = l.inputs.size();
  cp::Workspace ws(model);
  std::vector<Vec2> guess = ws.instant.x;
  std::vector<double> unit(dof, 0.0), zero(dof, 0.0);
  Kinematics out;
  out.samples.reserve(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    auto ok = cp::solve_position(model, ws, guess, values[i]);
    if (!ok) return Unexpected<cp::PlanarError>(ok.error());
    guess = ws.instant.x;
    Kinematics::Sample s;
    // the node velocities at unit rate of each input (the factorisation at the solved position
    // serves each: no new position solve)
    for (std::size_t d = 0; d < dof; ++d) {
      std::fill(unit.begin(), unit.end(), 0.0);
      unit[d] = 1.0;
      ok = cp::inverse_dynamics(model, ws, 0.0, unit, zero);
      if (!ok) return Unexpected<cp::PlanarError>(ok.error());
      s.unit_rate_velocity.push_back(ws.instant.v);
      s.unit_rate_omega.push_back(ws.instant.omega);
    }
    ok = cp::inverse_dynamics(model, ws, 0.0, rates[i], accelerations[i]);
    if (!ok) return Unexpected<cp::PlanarError>(ok.error());
    s.x = ws.instant.x;
    s.a = ws.instant.a;
    s.angle = ws.instant.angle;
    s.omega = ws.instant.omega;
    s.alpha = ws.instant.alpha;
    out.samples.push_back(std::move(s));
  }
  return out;
}

InputSeries input_series(const cp::Model& model, const core::Series& table) {
  const cp::Linkage& l = model.linkage();
  InputSeries out;
  std::vector<std::array<int, 3>> columns;  // per input: value, rate, acceleration
  for (const cp::Input& in : l.inputs) {
    const std::string name = in.kind == cp::Input::Kind::kAngle
                                 ? l.links[static_cast<std::size_t>(in.link)].name
                                 : l.sliders[static_cast<std::size_t>(in.slider)].name;
    const bool angle = in.kind == cp::Input::Kind::kAngle;
    columns.push_back({table.column((angle ? "theta_" : "s_") + name),
                       table.column((angle ? "omega_" : "v_") + name),
                       table.column((angle ? "alpha_" : "a_") + name)});
  }
  for (std::size_t r = 0; r < table.rows(); ++r) {
    std::vector<double> v, w, a;
    for (const auto& c : columns) {
      v.push_back(table.at(r, static_cast<std::size_t>(c[0])));
      w.push_back(table.at(r, static_cast<std::size_t>(c[1])));
      a.push_back(table.at(r, static_cast<std::size_t>(c[2])));
    }
    out.values.push_back(std::move(v));
    out.rates.push_back(std::move(w));
    out.accelerations.push_back(std::move(a));
  }
  return out;
}

Eigen::MatrixXd momentum_regressor(const cp::Linkage& l, const Kinematics& k) {
  const std::size_t dof = l.inputs.size();
  MatrixXd Z =
      MatrixXd::Zero(static_cast<Eigen::Index>(2 * dof * k.samples.size()), Parameters::count(l));
  Eigen::Index row = 0;
  for (const Kinematics::Sample& s : k.samples) {
    for (std::size_t d = 0; d < dof; ++d, row += 2) {
      const std::vector<Vec2>& v = s.unit_rate_velocity[d];
      for (std::size_t j = 0; j < l.links.size(); ++j) {
        const int i = static_cast<int>(j);
        const LinkFrame f = frame_of(l, i);
        const Vec2 vp = v[static_cast<std::size_t>(f.p)];
        const Vec2 dv = (v[static_cast<std::size_t>(f.q)] - vp) / f.length;
        Z.block<2, 1>(row, Parameters::link_mass(i)) = vp;
        Z.block<2, 1>(row, Parameters::link_me(i)) = dv;
        Z.block<2, 1>(row, Parameters::link_mf(i)) = perp(dv);
      }
      for (std::size_t j = 0; j < l.point_masses.size(); ++j) {
        Z.block<2, 1>(row, Parameters::point_mass(l, static_cast<int>(j))) =
            v[static_cast<std::size_t>(l.point_masses[j].node)];
      }
    }
  }
  return Z;
}

Eigen::MatrixXd shaking_force_regressor(const cp::Linkage& l, const Kinematics& k) {
  MatrixXd Y =
      MatrixXd::Zero(static_cast<Eigen::Index>(2 * k.samples.size()), Parameters::count(l));
  Eigen::Index row = 0;
  for (const Kinematics::Sample& s : k.samples) {
    for (std::size_t j = 0; j < l.links.size(); ++j) {
      const int i = static_cast<int>(j);
      const LinkFrame f = frame_of(l, i);
      const Vec2 ap = s.a[static_cast<std::size_t>(f.p)];
      const Vec2 da = (s.a[static_cast<std::size_t>(f.q)] - ap) / f.length;
      Y.block<2, 1>(row, Parameters::link_mass(i)) = -ap;
      Y.block<2, 1>(row, Parameters::link_me(i)) = -da;
      Y.block<2, 1>(row, Parameters::link_mf(i)) = -perp(da);
    }
    for (std::size_t j = 0; j < l.point_masses.size(); ++j) {
      Y.block<2, 1>(row, Parameters::point_mass(l, static_cast<int>(j))) =
          -s.a[static_cast<std::size_t>(l.point_masses[j].node)];
    }
    row += 2;
  }
  return Y;
}

Eigen::MatrixXd shaking_moment_regressor(const cp::Linkage& l, const Kinematics& k) {
  MatrixXd Y = MatrixXd::Zero(static_cast<Eigen::Index>(k.samples.size()), Parameters::count(l));
  Eigen::Index row = 0;
  for (const Kinematics::Sample& s : k.samples) {
    for (std::size_t j = 0; j < l.links.size(); ++j) {
      const int i = static_cast<int>(j);
      const LinkFrame f = frame_of(l, i);
      const Vec2 xp = s.x[static_cast<std::size_t>(f.p)], ap = s.a[static_cast<std::size_t>(f.p)];
      const double w = s.omega[j], al = s.alpha[j];
      const Vec2 u = unit(s.angle[j]), n = perp(u);
      // dH/dt of a link about the origin, with r = c - p = (m e u + m f n)/m rotating with it:
      //   cross(p, m a_p) + cross(p, α perp(m r) - ω² m r) + cross(m r, a_p) + J α
      auto first_moment_term = [&](const Vec2& dir) {
        return cross(xp, al * perp(dir) - w * w * dir) + cross(dir, ap);
      };
      Y(row, Parameters::link_mass(i)) = -cross(xp, ap);
      Y(row, Parameters::link_me(i)) = -first_moment_term(u);
      Y(row, Parameters::link_mf(i)) = -first_moment_term(n);
      Y(row, Parameters::link_J(i)) = -al;
    }
    for (std::size_t j = 0; j < l.point_masses.size(); ++j) {
      const std::size_t n = static_cast<std::size_t>(l.point_masses[j].node);
      Y(row, Parameters::point_mass(l, static_cast<int>(j))) = -cross(s.x[n], s.a[n]);
    }
    ++row;
  }
  return Y;
}

Eigen::MatrixXd angular_momentum_regressor(const cp::Linkage& l, const Kinematics& k) {
  const std::size_t dof = l.inputs.size();
  MatrixXd H =
      MatrixXd::Zero(static_cast<Eigen::Index>(dof * k.samples.size()), Parameters::count(l));
  Eigen::Index row = 0;
  for (const Kinematics::Sample& s : k.samples) {
    for (std::size_t d = 0; d < dof; ++d, ++row) {
      const std::vector<Vec2>& v = s.unit_rate_velocity[d];
      for (std::size_t j = 0; j < l.links.size(); ++j) {
        const int i = static_cast<int>(j);
        const LinkFrame f = frame_of(l, i);
        const std::size_t p = static_cast<std::size_t>(f.p);
        const Vec2 xp = s.x[p], vp = v[p];
        const double w = s.unit_rate_omega[d][j];
        const Vec2 u = unit(s.angle[j]), n = perp(u);
        // H of a rigid link about the origin, with r = c - p = (m e u + m f n)/m rotating with
        // it and S = m r: m p × v_p + ω (p · S) + S × v_p + J ω
        H(row, Parameters::link_mass(i)) = cross(xp, vp);
        H(row, Parameters::link_me(i)) = w * xp.dot(u) + cross(u, vp);
        H(row, Parameters::link_mf(i)) = w * xp.dot(n) + cross(n, vp);
        H(row, Parameters::link_J(i)) = w;
      }
      for (std::size_t j = 0; j < l.point_masses.size(); ++j) {
        const std::size_t n = static_cast<std::size_t>(l.point_masses[j].node);
        H(row, Parameters::point_mass(l, static_cast<int>(j))) = cross(s.x[n], v[n]);
      }
    }
  }
  return H;
}

ShaftSeries shaft_series(const cp::Linkage& l, const Kinematics& k) {
  const std::size_t dof = l.inputs.size(), n = k.samples.size();
  ShaftSeries out{VectorXd::Zero(static_cast<Eigen::Index>(2 * dof * n)),
                  VectorXd::Zero(static_cast<Eigen::Index>(2 * n)),
                  VectorXd::Zero(static_cast<Eigen::Index>(n)),
                  VectorXd::Zero(static_cast<Eigen::Index>(dof * n))};
  for (const cp::BalanceShaft& b : l.shafts) {
    const LinkFrame f = frame_of(l, b.link);
    const std::size_t L = static_cast<std::size_t>(b.link);
    for (std::size_t i = 0; i < n; ++i) {
      const Kinematics::Sample& s = k.samples[i];
      const Vec2 r = cp::shaft_centre(b, s.angle[L] - f.angle);
      const double w = b.ratio * s.omega[L], al = b.ratio * s.alpha[L];
      const Vec2 a = al * perp(r) - w * w * r;
      for (std::size_t j = 0; j < dof; ++j) {
        const double rate = s.unit_rate_omega[j][L];
        out.momentum.segment<2>(static_cast<Eigen::Index>(2 * (i * dof + j))) +=
            b.mass * b.ratio * rate * perp(r);
        // spin about its centre of mass, and its centre's turn about the shaft seen from O
        out.angular_momentum[static_cast<Eigen::Index>(i * dof + j)] +=
            b.ratio * rate * (b.inertia + b.mass * (b.at + r).dot(r));
      }
      out.force.segment<2>(static_cast<Eigen::Index>(2 * i)) -= b.mass * a;
      out.moment[static_cast<Eigen::Index>(i)] -= b.inertia * al + cross(b.at + r, b.mass * a);
    }
  }
  return out;
}

bool force_balanced(const cp::Linkage& l, const Kinematics& k) {
  const MatrixXd Z = momentum_regressor(l, k);
  const VectorXd theta = Parameters::of(l);
  const VectorXd momentum = shaft_series(l, k).momentum;
  return cancels(Z * theta + momentum, (Z.cwiseAbs() * theta.cwiseAbs()).norm() + momentum.norm());
}

cp::Link merged(const cp::Link& link, const Counterweight& cw, const Vec2& from_first) {
  const double m = link.mass, mc = cw.mass, M = m + mc;
  const Vec2 s(link.e, link.f);
  const Vec2 c = (m * s + mc * from_first) / M;
  cp::Link out = link;
  out.mass = M;
  out.e = c.x();
  out.f = c.y();
  out.inertia =
      link.inertia + m * (s - c).squaredNorm() + cw.inertia + mc * (from_first - c).squaredNorm();
  return out;
}

namespace {

// one counterweight to place: its link, pivot, the pivot in link axes, and what is known
struct Placement {
  LinkCounterweightSpec ask;
  int pivot{};
  bool grounded{};
  Vec2 pivot_in_link{0, 0};  // from the link's first node [m]
  double scale{};            // the unknowns' weight: the distance a counterweight sits at [m]
  double fixed_mass{};       // a floating link's given mass [kg] (0 for a grounded link)
};

std::vector<Placement> placements(const cp::Linkage& l,
                                  const std::vector<LinkCounterweightSpec>& asks) {
  std::vector<Placement> out;
  std::set<int> seen;
  for (const LinkCounterweightSpec& ask : asks) {
    const cp::Link& link = l.links.at(static_cast<std::size_t>(ask.link));
    const std::string field = "counterweights." + link.name;
    if (const Problem p = ask.spec.validate()) {
      // the spec's own field under the link's: counterweights.crank.mass
      throw InputError(FieldError{p->field.empty() ? field : field + "." + p->field, -1,
                                  p->field.empty() ? ": " + p->message : p->message});
    }
    if (!seen.insert(ask.link).second)
      throw InputError(FieldError{field, -1, ": one counterweight per link"});
    Placement pl;
    pl.ask = ask;
    std::vector<int> grounds;
    for (int n : link.nodes)
      if (l.nodes[static_cast<std::size_t>(n)].ground) grounds.push_back(n);
    if (grounds.size() > 1)
      throw InputError(FieldError{field, -1, ": the link is fixed to the frame at two nodes"});
    pl.grounded = grounds.size() == 1;
    pl.pivot = pl.grounded ? grounds[0] : link.nodes[0];
    pl.pivot_in_link =
        in_link_axes(l, ask.link, l.nodes[static_cast<std::size_t>(pl.pivot)].position);
    const double length = frame_of(l, ask.link).length;
    const CounterweightSpec& spec = ask.spec;
    if (!pl.grounded) {
      if (spec.mass) {
        pl.fixed_mass = *spec.mass;
      } else if (spec.radius) {
        pl.fixed_mass =
            spec.density * std::numbers::pi * spec.thickness * *spec.radius * *spec.radius;
      } else {
        throw InputError(FieldError{field, -1,
                                    ": the link does not turn about the frame, so its "
                                    "counterweight's mass moves the node masses too: give its "
                                    "mass (or a disc's radius) and its position is solved"});
      }
    }
    pl.scale = spec.distance ? *spec.distance : length;
    out.push_back(pl);
  }
  return out;
}

// the parameter change a counterweight of mass `mass` with first moment `w` about its pivot
// (link axes) makes
void add_counterweight(VectorXd& theta, const Placement& pl, double mass, const Vec2& w) {
  const int k = pl.ask.link;
  theta[Parameters::link_mass(k)] += mass;
  theta[Parameters::link_me(k)] += mass * pl.pivot_in_link.x() + w.x();
  theta[Parameters::link_mf(k)] += mass * pl.pivot_in_link.y() + w.y();
}

// min-norm least squares of A x = b with x's pairs weighted by the placements' scales
VectorXd solve_moments(const MatrixXd& R, const VectorXd& theta0, const VectorXd& fixed,
                       const std::vector<Placement>& pls) {
  if (pls.empty()) return VectorXd();
  MatrixXd A(R.rows(), static_cast<Eigen::Index>(2 * pls.size()));
  for (std::size_t i = 0; i < pls.size(); ++i) {
    const int k = pls[i].ask.link;
    A.col(static_cast<Eigen::Index>(2 * i)) = pls[i].scale * R.col(Parameters::link_me(k));
    A.col(static_cast<Eigen::Index>(2 * i + 1)) = pls[i].scale * R.col(Parameters::link_mf(k));
  }
  const VectorXd b = -(R * theta0 + fixed);
  Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(A);
  VectorXd x = cod.solve(b);
  for (std::size_t i = 0; i < pls.size(); ++i)
    x.segment<2>(static_cast<Eigen::Index>(2 * i)) *= pls[i].scale;
  return x;
}

// the rank of the momentum conditions, columns scaled to one unit (m by the length scale)
int condition_rank(const MatrixXd& Z, const cp::Linkage& l, double length) {
  MatrixXd S = Z;
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    S.col(Parameters::link_me(static_cast<int>(k))) *= length;
    S.col(Parameters::link_mf(static_cast<int>(k))) *= length;
  }
  Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(S);
  cod.setThreshold(1e-10);
  return static_cast<int>(cod.rank());
}

}  // namespace

int force_balance_conditions(const cp::Linkage& linkage, const Kinematics& k) {
  double length = 0;
  for (std::size_t j = 0; j < linkage.links.size(); ++j)
    length = std::max(length, frame_of(linkage, static_cast<int>(j)).length);
  return condition_rank(momentum_regressor(linkage, k), linkage, length);
}

Expected<Kinematics, cp::PlanarError> crank_revolution(const cp::Model& model, int samples,
                                                       std::vector<double>* angles) {
  const double start = cp::drawn_inputs(model)[0];
  std::vector<std::vector<double>> values, rates, accelerations;
  for (int j = 0; j < samples; ++j) {
    values.push_back({start + 2 * std::numbers::pi * j / samples});
    rates.push_back({1.0});
    accelerations.push_back({0.0});
  }
  if (angles) {
    angles->clear();
    for (const auto& v : values) angles->push_back(v[0]);
  }
  return kinematics(model, values, rates, accelerations);
}

std::vector<LinkCounterweightSpec> grounded_links(const cp::Linkage& l) {
  std::vector<LinkCounterweightSpec> out;
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    int grounds = 0;
    for (int n : l.links[k].nodes) grounds += l.nodes[static_cast<std::size_t>(n)].ground ? 1 : 0;
    if (grounds == 1) out.push_back({static_cast<int>(k), {}});
  }
  return out;
}

void check_counterweights(const cp::Linkage& linkage,
                          const std::vector<LinkCounterweightSpec>& counterweights) {
  (void)placements(linkage, counterweights);
}

namespace {

// the crank counterweight's first moment about its pivot, in the crank's link axes, by an
// engine's balancing factor β: μ_A + p/|OA| = -β μ_B (force_balance's comment)
Vec2 by_balancing_factor(const cp::Linkage& l, const std::vector<Placement>& pls, double beta,
                         std::string& what) {
  auto refuse = [](const std::string& why) {
    throw InputError(FieldError{"balancing_factor", -1, ": " + why});
  };
  if (!std::isfinite(beta) || beta < 0) refuse("must be a number >= 0");
  if (pls.size() != 1 || !pls[0].grounded ||
      l.links[static_cast<std::size_t>(pls[0].ask.link)].nodes.size() != 2) {
    refuse(
        "applies to one counterweight, on a crank: a binary link that turns about a ground node");
  }
  const int crank = pls[0].ask.link, O = pls[0].pivot;
  const auto& cn = l.links[static_cast<std::size_t>(crank)].nodes;
  const int A = cn[0] == O ? cn[1] : cn[0];
  int B = -1;  // the piston: across a binary rod from A, on a frame guide
  for (std::size_t r = 0; r < l.links.size(); ++r) {
    const auto& nodes = l.links[r].nodes;
    if (static_cast<int>(r) == crank || nodes.size() != 2) continue;
    if (nodes[0] != A && nodes[1] != A) continue;
    const int other = nodes[0] == A ? nodes[1] : nodes[0];
    for (const cp::Slider& sl : l.sliders) {
      if (sl.link < 0 && sl.node == other) {
        if (B >= 0) refuse("the crank drives more than one piston; balance it with counterweights");
        B = other;
      }
    }
  }
  const std::string crank_name = l.links[static_cast<std::size_t>(crank)].name;
  if (B < 0) refuse("crank " + crank_name + " drives no piston through a connecting rod");
  const std::vector<ComplexMass> mu = equivalent_masses(l);
  const Vec2 OA =
      l.nodes[static_cast<std::size_t>(A)].position - l.nodes[static_cast<std::size_t>(O)].position;
  const ComplexMass p =
      -OA.norm() * (mu[static_cast<std::size_t>(A)] + beta * mu[static_cast<std::size_t>(B)]);
  // from the axes O->A to the link's axes (first to second node)
  const double turn = std::atan2(OA.y(), OA.x()) - frame_of(l, crank).angle;
  const ComplexMass w = p * std::polar(1.0, turn);
  what = "balancing factor " + text::digits(beta, 4) + ": the counterweight on " + crank_name +
         " balances the rotating mass at " + l.nodes[static_cast<std::size_t>(A)].name + " and " +
         text::digits(100 * beta, 4) + " % of the reciprocating mass at " +
         l.nodes[static_cast<std::size_t>(B)].name;
  return {w.real(), w.imag()};
}

// one line naming the node whose momentum is the largest part of what is left
std::string unbalanced_message(const cp::Linkage& l, const ForceBalance& out, const Kinematics& k,
                               const std::vector<Placement>& pls) {
  const std::vector<ComplexMass> mu = equivalent_masses(out.linkage);
  std::vector<double> share(l.nodes.size(), 0.0);
  for (const Kinematics::Sample& s : k.samples)
    for (const std::vector<Vec2>& v : s.unit_rate_velocity)
      for (std::size_t n = 0; n < l.nodes.size(); ++n)
        share[n] += std::norm(mu[n]) * v[n].squaredNorm();
  const std::size_t worst =
      static_cast<std::size_t>(std::max_element(share.begin(), share.end()) - share.begin());
  std::string links;
  for (const Placement& pl : pls)
    links += (links.empty() ? "" : ", ") + l.links[static_cast<std::size_t>(pl.ask.link)].name;
  // nodes that slide on frame guides (pistons) carry a reciprocating mass that no counterweight
  // on a turning link cancels: where there are any, they are what is left, whatever part of the
  // momentum the least-squares design leaves at the nodes that turn (a crank pin's, there on
  // purpose to cancel the pistons' first order in part)
  std::string pistons;
  double reciprocating = 0;
  for (const cp::Slider& sl : l.sliders) {
    const auto n = static_cast<std::size_t>(sl.node);
    if (sl.link >= 0 || !(std::abs(mu[n]) > 1e-12 * cp::total_mass(l))) continue;
    pistons += (pistons.empty() ? "" : ", ") + l.nodes[n].name;
    reciprocating += std::abs(mu[n]);
  }
  const std::string left =
      pistons.empty()
          ? "the largest part of the linear momentum left is node " + l.nodes[worst].name +
                "'s (equivalent mass " + text::digits(std::abs(mu[worst]), 4) + " kg)"
          : "the reciprocating mass at " + pistons + " (" + text::digits(reciprocating, 4) +
                " kg, sliding on frame guides) cannot be cancelled by counterweights on turning "
                "links";
  return "full force balance cannot be reached with counterweights on " +
         (links.empty() ? std::string("no link") : links) + ": " + left +
         "; the least-squares design leaves " +
         "the RMS inertial shaking force at " +
         text::digits(out.Fsh_rms_before > 0 ? 100 * out.Fsh_rms_after / out.Fsh_rms_before : 0.0,
                      3) +
         " % of the original";
}

}  // namespace

void check_balancing_factor(const cp::Linkage& linkage,
                            const std::vector<LinkCounterweightSpec>& counterweights, double beta) {
  std::string rule;
  (void)by_balancing_factor(linkage, placements(linkage, counterweights), beta, rule);
}

ForceBalance force_balance(const cp::Linkage& linkage, const Kinematics& k,
                           const std::vector<LinkCounterweightSpec>& counterweights,
                           std::optional<double> balancing_factor) {
  const cp::Linkage& l = linkage;
  const std::vector<Placement> pls = placements(l, counterweights);
  double length = 0;
  for (std::size_t j = 0; j < l.links.size(); ++j)
    length = std::max(length, frame_of(l, static_cast<int>(j)).length);
  const double total_mass = cp::total_mass(l);

  const VectorXd theta0 = Parameters::of(l);
  VectorXd theta_fixed = theta0;  // with the floating counterweights' given masses at their pivots
  for (const Placement& pl : pls)
    if (!pl.grounded) add_counterweight(theta_fixed, pl, pl.fixed_mass, Vec2(0, 0));
  const MatrixXd Z = momentum_regressor(l, k), Y = shaking_force_regressor(l, k);
  const ShaftSeries shafts = shaft_series(l, k);

  ForceBalance out;
  out.balancing_factor = balancing_factor;
  out.conditions = condition_rank(Z, l, length);
  const double before = (Z * theta0 + shafts.momentum).norm();
  std::string rule;
  VectorXd x = balancing_factor ? VectorXd(by_balancing_factor(l, pls, *balancing_factor, rule))
                                : solve_moments(Z, theta_fixed, shafts.momentum, pls);
  auto design = [&](const VectorXd& moments) {
    VectorXd theta = theta_fixed;
    for (std::size_t i = 0; i < pls.size(); ++i)
      add_counterweight(theta, pls[i], 0.0, moments.segment<2>(static_cast<Eigen::Index>(2 * i)));
    return theta;
  };
  VectorXd theta = design(x);
  // what cancels to round-off: the momentum left against the sum of its terms' sizes
  const double terms = (Z.cwiseAbs() * theta.cwiseAbs()).norm() + shafts.momentum.norm();
  out.full = !balancing_factor && cancels(Z * theta + shafts.momentum, terms);
  if (!out.full && !balancing_factor) {
    // the least RMS inertial shaking force over the motion instead
    x = solve_moments(Y, theta_fixed, shafts.force, pls);
    theta = design(x);
  }
  out.momentum_left = before > 0 ? (Z * theta + shafts.momentum).norm() / before : 0.0;
  out.Fsh_rms_before = rms_of_pairs(Y * theta0 + shafts.force);
  out.Fsh_rms_after = rms_of_pairs(Y * theta + shafts.force);

  // realise each counterweight and merge it into its link
  out.linkage = l;
  for (std::size_t i = 0; i < pls.size(); ++i) {
    const Placement& pl = pls[i];
    const Vec2 w = x.segment<2>(static_cast<Eigen::Index>(2 * i));
    if (w.norm() <= 1e-13 * total_mass * length && pl.grounded) continue;  // balanced already
    const Counterweight cw = realise(pl.ask.spec, w, pl.scale);
    LinkCounterweight added{pl.ask.link, pl.pivot, cw};
    cp::Link& link = out.linkage.links[static_cast<std::size_t>(pl.ask.link)];
    link = merged(link, cw, pl.pivot_in_link + cw.position);
    out.added_mass += cw.mass;
    out.added_inertia += cw.inertia + cw.mass * cw.distance * cw.distance;
    out.added.push_back(added);
  }
  if (balancing_factor) {
    out.message =
        rule + "; the RMS inertial shaking force is " +
        text::digits(out.Fsh_rms_before > 0 ? 100 * out.Fsh_rms_after / out.Fsh_rms_before : 0.0,
                     3) +
        " % of the original";
  } else if (!out.full) {
    out.message = unbalanced_message(l, out, k, pls);
  }
  // a floating link's counterweight has its mass given and its place solved: say where that
  // place is far outside the linkage (a mass too small for the moment it must carry)
  for (const LinkCounterweight& a : out.added) {
    const double reach = frame_of(l, a.link).length;
    if (a.counterweight.distance > 3 * reach) {
      out.message += std::string(out.message.empty() ? "" : "; ") + "the counterweight on " +
                     l.links[static_cast<std::size_t>(a.link)].name + " sits " +
                     text::digits(a.counterweight.distance, 4) + " m from its pivot, " +
                     text::digits(a.counterweight.distance / reach, 3) +
                     " times the link's length: give it more mass to bring it closer";
    }
  }
  return out;
}

}  // namespace bd::balance::planar
