#include "balance/planar_shafts.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "core/planar/dynamics.hpp"

namespace bd::balance::planar {

namespace {

constexpr int kSamples = 720;  // per revolution: orders far above any asked for alias nothing

[[noreturn]] void refuse(const std::string& why) {
  throw InputError(FieldError{"shafts", -1, ": " + why});
}

// the crank's revolution at unit speed: its kinematics and the crank angles
struct Revolution {
  Kinematics k;
  std::vector<double> angle;
};
Revolution revolution(const cp::Linkage& l) {
  Revolution r;
  auto k = crank_revolution(cp::Model(l), kSamples, &r.angle);
  if (!k) {
    refuse("balance shafts need a crank that turns a full revolution; " + l.inputs[0].name +
           " cannot (" + k.error().detail + ")");
  }
  r.k = std::move(*k);
  return r;
}

// C_k of the force series (x0, y0, x1, ...) over the revolution: (1/N) Σ F_j e^{-ikθ_j}
std::complex<double> coefficient(const Eigen::VectorXd& force, const std::vector<double>& angle,
                                 int k) {
  std::complex<double> sum = 0;
  for (std::size_t j = 0; j < angle.size(); ++j) {
    const std::complex<double> F(force[static_cast<Eigen::Index>(2 * j)],
                                 force[static_cast<Eigen::Index>(2 * j + 1)]);
    sum += F * std::polar(1.0, -k * angle[j]);
  }
  return sum / static_cast<double>(angle.size());
}

Eigen::VectorXd inertial_force(const cp::Linkage& l, const Kinematics& k) {
  return shaking_force_regressor(l, k) * Parameters::of(l) + shaft_series(l, k).force;
}

}  // namespace

ShaftBalance balance_shafts(const cp::Linkage& linkage, const ShaftRequest& request) {
  const cp::Linkage& l = linkage;
  if (l.inputs.size() != 1 || l.inputs[0].kind != cp::Input::Kind::kAngle) {
    refuse("balance shafts are geared to a crank: the linkage needs one input, a link's angle");
  }
  if (request.orders.empty()) refuse("name the orders to cancel, e.g. orders: [1, 2]");
  for (std::size_t i = 0; i < request.orders.size(); ++i) {
    const int n = request.orders[i];
    if (n < 1) refuse("orders must be whole numbers >= 1, got " + std::to_string(n));
    for (std::size_t j = 0; j < i; ++j) {
      if (request.orders[j] == n) {
        refuse("orders[" + std::to_string(i) + "] repeats order " + std::to_string(n) +
               " (orders[" + std::to_string(j) + "])");
      }
    }
  }
  ShaftBalance out;
  out.crank = l.inputs[0].link;
  out.linkage = l;
  const int pivot = cp::pivot_of(l, out.crank);
  const Vec2 at = request.at ? *request.at : l.nodes[static_cast<std::size_t>(pivot)].position;
  const double radius = request.radius ? *request.radius : cp::element_length(l, out.crank);
  if (!(radius > 0) || !std::isfinite(radius)) refuse("radius must be > 0 m");
  const Revolution rev = revolution(l);
  const double drawn = rev.angle[0];
  const Eigen::VectorXd before = inertial_force(l, rev.k);
  // a rotating part below 1e-12 of the linkage's scale gets no shaft: the RMS force, or, where
  // counterweights have balanced it to round-off, the force its moving mass would shake with at
  // the largest link's length (the revolution is at unit speed)
  double reach = 0;
  for (std::size_t k = 0; k < l.links.size(); ++k)
    reach = std::max(reach, cp::element_length(l, static_cast<int>(k)));
  const double size =
      std::max(std::sqrt(before.squaredNorm() / kSamples), cp::total_mass(l) * reach) + 1e-300;
  for (int n : request.orders) {
    for (int k : {n, -n}) {
      const std::complex<double> C = coefficient(before, rev.angle, k);
      if (std::abs(C) <= 1e-12 * size) continue;
      const std::complex<double> me = -C * std::polar(1.0, k * drawn) / double(k * k);
      cp::BalanceShaft b;
      b.name = "shaft_" + std::to_string(k);
      if (cp::node_index(l, b.name) >= 0) refuse("the name " + b.name + " is a node's");
      for (const cp::BalanceShaft& s : out.linkage.shafts) {
        if (s.name == b.name) refuse("the linkage has a shaft named " + b.name + " already");
      }
      b.link = out.crank;
      b.ratio = k;
      const auto own = request.at_shaft.find(k);
      b.at = own != request.at_shaft.end() ? own->second : at;
      b.mass = std::abs(me) / radius;
      b.eccentricity = Vec2(me.real(), me.imag()) / b.mass;
      out.added.push_back(static_cast<int>(out.linkage.shafts.size()));
      out.linkage.shafts.push_back(b);
    }
  }
  out.linkage = cp::make_linkage(out.linkage);
  const Eigen::VectorXd after = inertial_force(out.linkage, rev.k);
  for (int n : request.orders) {
    out.orders.push_back({n, std::abs(coefficient(before, rev.angle, n)),
                          std::abs(coefficient(before, rev.angle, -n)),
                          std::abs(coefficient(after, rev.angle, n)),
                          std::abs(coefficient(after, rev.angle, -n))});
  }
  return out;
}

void add_shafts(ForceBalance& design, const ShaftBalance& shafts, const Kinematics& k,
                const cp::Linkage& original) {
  const cp::Linkage& l = shafts.linkage;
  std::string names, orders;
  for (int i : shafts.added) {
    const cp::BalanceShaft& b = l.shafts[static_cast<std::size_t>(i)];
    design.added_mass += b.mass;
    design.added_inertia += b.inertia + b.mass * b.eccentricity.squaredNorm();
    names += (names.empty() ? "" : ", ") + b.name;
  }
  for (const ShaftBalance::Order& o : shafts.orders) {
    orders += (orders.empty() ? "" : ", ") + std::to_string(o.order);
  }
  const Eigen::VectorXd theta = Parameters::of(l);
  const ShaftSeries s = shaft_series(l, k);
  const Eigen::VectorXd F = shaking_force_regressor(l, k) * theta + s.force;
  const double before = design.Fsh_rms_before;
  design.Fsh_rms_after = std::sqrt(F.squaredNorm() / static_cast<double>(k.samples.size()));
  const double momentum0 = (momentum_regressor(original, k) * Parameters::of(original) +
                            shaft_series(original, k).momentum)
                               .norm();
  if (momentum0 > 0)
    design.momentum_left = (momentum_regressor(l, k) * theta + s.momentum).norm() / momentum0;
  design.linkage = l;
  const std::string what = (names.empty() ? std::string("no balance shaft is needed for order")
                                          : "balance shafts " + names + " cancel order") +
                           (shafts.orders.size() > 1 ? "s " : " ") + orders +
                           " of the shaking force; the RMS " + "inertial shaking force is " +
                           text::digits(before > 0 ? 100 * design.Fsh_rms_after / before : 0.0, 3) +
                           " % of the original";
  design.message = design.message.empty() ? what : design.message + "; " + what;
}

}  // namespace bd::balance::planar
