#include "balance/planar_moment.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <set>

#include "core/input_error.hpp"
#include "core/number_text.hpp"
#include "core/planar/model.hpp"

namespace bd::balance::planar {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

[[noreturn]] void refuse(const cp::Linkage& l, const CounterRotationRequest& r,
                         const std::string& why) {
  throw InputError(FieldError{"counter_rotations." + l.links[static_cast<std::size_t>(r.link)].name,
                              -1, ": " + why});
}

std::string shaft_name(const cp::Linkage& l, int link) {
  return "counter_" + l.links[static_cast<std::size_t>(link)].name;
}

// per (sample, input) row: each requested link's rate per unit rate of the input
MatrixXd link_rates(const cp::Linkage& l, const Kinematics& k,
                    const std::vector<CounterRotationRequest>& requests) {
  const std::size_t dof = l.inputs.size();
  MatrixXd W(static_cast<Eigen::Index>(dof * k.samples.size()),
             static_cast<Eigen::Index>(requests.size()));
  Eigen::Index row = 0;
  for (const Kinematics::Sample& s : k.samples) {
    for (std::size_t d = 0; d < dof; ++d, ++row) {
      for (std::size_t c = 0; c < requests.size(); ++c) {
        W(row, static_cast<Eigen::Index>(c)) =
            s.unit_rate_omega[d][static_cast<std::size_t>(requests[c].link)];
      }
    }
  }
  return W;
}

// per sample: the inertial shaking moment of a unit coefficient c = k J on each link, -α_L
MatrixXd moment_columns(const Kinematics& k, const std::vector<CounterRotationRequest>& requests) {
  MatrixXd A(static_cast<Eigen::Index>(k.samples.size()),
             static_cast<Eigen::Index>(requests.size()));
  for (std::size_t i = 0; i < k.samples.size(); ++i)
    for (std::size_t c = 0; c < requests.size(); ++c)
      A(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) =
          -k.samples[i].alpha[static_cast<std::size_t>(requests[c].link)];
  return A;
}

// the coefficients that minimise the RMS shaking moment |Msh + A c| over the samples and, among
// those, the angular momentum |h + W c| over the configurations: a disc on a link that turns at
// constant speed in the scene (the driven crank) changes nothing in the scene, and is chosen for
// the motions whose speed varies
VectorXd least_squares(const MatrixXd& A, const VectorXd& Msh, const MatrixXd& W,
                       const VectorXd& h) {
  Eigen::JacobiSVD<MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeFullV);
  svd.setThreshold(1e-10);
  VectorXd c = svd.solve(-Msh);
  const Eigen::Index rank = svd.rank();
  if (rank < A.cols()) {
    const MatrixXd N = svd.matrixV().rightCols(A.cols() - rank);
    c += N * Eigen::CompleteOrthogonalDecomposition<MatrixXd>(W * N).solve(-(h + W * c));
  }
  return c;
}

double rms(const VectorXd& v) {
  return v.size() > 0 ? std::sqrt(v.squaredNorm() / static_cast<double>(v.size())) : 0.0;
}

// the name of the part (link, point mass or shaft) whose angular momentum is the largest part
// of what the counter-rotations cannot cancel (what is left after projecting out their span)
std::string largest_part_left(const cp::Linkage& l, const MatrixXd& Hm, const VectorXd& theta,
                              const ShaftSeries& shafts, const MatrixXd& W) {
  const Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(W);
  auto left = [&](const VectorXd& h) {
    return W.cols() > 0 ? (h - W * cod.solve(h)).norm() : h.norm();
  };
  std::string name;
  double largest = -1;
  auto consider = [&](const VectorXd& h, const std::string& what) {
    const double r = left(h);
    if (r > largest) {
      largest = r;
      name = what;
    }
  };
  for (std::size_t j = 0; j < l.links.size(); ++j) {
    const int i = static_cast<int>(j);
    const int c0 = Parameters::link_mass(i);
    consider(Hm.middleCols(c0, 4) * theta.segment(c0, 4), "link " + l.links[j].name + "'s");
  }
  for (std::size_t j = 0; j < l.point_masses.size(); ++j) {
    const int c = Parameters::point_mass(l, static_cast<int>(j));
    consider(Hm.col(c) * theta[c],
             "the point mass at " + l.nodes[static_cast<std::size_t>(l.point_masses[j].node)].name +
                 "'s");
  }
  if (!l.shafts.empty()) consider(shafts.angular_momentum, "the balance shafts'");
  return name;
}

}  // namespace

std::vector<CounterRotationRequest> default_counter_rotations(const cp::Linkage& l) {
  std::vector<CounterRotationRequest> out;
  for (const LinkCounterweightSpec& g : grounded_links(l)) out.push_back({g.link, std::nullopt});
  return out;
}

Vec2 shaft_position(const cp::Linkage& l, const CounterRotationRequest& r) {
  if (r.at) return *r.at;
  const int pivot = cp::pivot_of(l, r.link);
  return l.nodes[static_cast<std::size_t>(pivot)].position - Vec2(0, cp::element_length(l, r.link));
}

void check_counter_rotations(const cp::Linkage& l,
                             const std::vector<CounterRotationRequest>& requests) {
  std::set<std::string> names;
  for (const cp::Node& n : l.nodes) names.insert(n.name);
  for (const cp::Slider& s : l.sliders) names.insert(s.name);
  for (const cp::BalanceShaft& b : l.shafts) names.insert(b.name);
  std::set<int> seen;
  for (const CounterRotationRequest& r : requests) {
    if (r.link < 0 || r.link >= static_cast<int>(l.links.size()))
      throw InputError(FieldError{"counter_rotations", -1, ": not a link"});
    if (!seen.insert(r.link).second) refuse(l, r, "one counter-rotation per link");
    if (cp::pivot_of(l, r.link) < 0) {
      refuse(l, r,
             "the link does not turn about one ground node; a counter-rotation is geared to a "
             "link pivoted on the frame");
    }
    if (r.at && !(std::isfinite(r.at->x()) && std::isfinite(r.at->y())))
      refuse(l, r, "at must be finite");
    if (names.count(shaft_name(l, r.link)) > 0) {
      refuse(l, r,
             "its shaft's name " + shaft_name(l, r.link) +
                 " is a node's, a slider's or a balance shaft's already");
    }
  }
}

MomentBalance moment_balance(const cp::Linkage& linkage, const Kinematics& k,
                             const std::vector<CounterRotationRequest>& requests) {
  const cp::Linkage& l = linkage;
  check_counter_rotations(l, requests);
  if (!force_balanced(l, k)) {
    throw InputError(
        "a moment balance starts from a fully force-balanced design, and this one keeps linear "
        "momentum (its shaking moment then depends on the point it is taken about)");
  }
  const VectorXd theta = Parameters::of(l);
  const ShaftSeries shafts = shaft_series(l, k);
  const MatrixXd Hm = angular_momentum_regressor(l, k), W = link_rates(l, k, requests);
  const VectorXd h = Hm * theta + shafts.angular_momentum;
  const VectorXd Msh = shaking_moment_regressor(l, k) * theta + shafts.moment;
  const MatrixXd A = moment_columns(k, requests);

  MomentBalance out;
  VectorXd c = requests.empty()
                   ? VectorXd()
                   : VectorXd(Eigen::CompleteOrthogonalDecomposition<MatrixXd>(W).solve(-h));
  auto left = [&] { return requests.empty() ? h : VectorXd(h + W * c); };
  const double terms = (Hm.cwiseAbs() * theta.cwiseAbs()).norm() + shafts.angular_momentum.norm() +
                       (requests.empty() ? 0.0 : (W.cwiseAbs() * c.cwiseAbs()).norm());
  out.full = left().norm() <= 1e-10 * std::max(terms, 1e-300);
  if (!out.full && !requests.empty()) c = least_squares(A, Msh, W, h);
  out.angular_momentum_left = h.norm() > 0 ? left().norm() / h.norm() : 0.0;
  out.Msh_rms_before = rms(Msh);
  out.Msh_rms_after = requests.empty() ? rms(Msh) : rms(Msh + A * c);

  out.linkage = l;
  for (std::size_t i = 0; i < requests.size(); ++i) {
    const double ci = c[static_cast<Eigen::Index>(i)];
    // a link whose own angular momentum cancels already gets no disc
    if (std::abs(ci) * W.col(static_cast<Eigen::Index>(i)).norm() <=
        1e-10 * std::max(terms, 1e-300))
      continue;
    cp::BalanceShaft b;
    b.name = shaft_name(l, requests[i].link);
    b.link = requests[i].link;
    b.ratio = ci < 0 ? -1 : 1;
    b.at = shaft_position(l, requests[i]);
    b.inertia = std::abs(ci);
    out.added_inertia += b.inertia;
    out.added.push_back(static_cast<int>(out.linkage.shafts.size()));
    out.linkage.shafts.push_back(b);
  }
  out.linkage = cp::make_linkage(out.linkage);
  if (!out.full) {
    std::string links;
    for (const CounterRotationRequest& r : requests)
      links += (links.empty() ? "" : ", ") + l.links[static_cast<std::size_t>(r.link)].name;
    out.message =
        "full moment balance cannot be reached with counter-rotations on " +
        (links.empty() ? std::string("no link") : links) +
        ": the largest part of the angular momentum they cannot cancel is " +
        largest_part_left(l, Hm, theta, shafts, W) +
        "; the least-squares counter-rotations leave the RMS inertial shaking moment at " +
        text::digits(out.Msh_rms_before > 0 ? 100 * out.Msh_rms_after / out.Msh_rms_before : 0.0,
                     3) +
        " % of the force-balanced design's";
  }
  return out;
}

void add_counter_rotations(ForceBalance& design, const MomentBalance& moment) {
  design.linkage = moment.linkage;
  design.added_inertia += moment.added_inertia;
  std::string names;
  for (int i : moment.added)
    names += (names.empty() ? "" : ", ") + moment.linkage.shafts[static_cast<std::size_t>(i)].name;
  const std::string what =
      moment.full ? (names.empty() ? std::string("the design is moment balanced already")
                                   : "counter-rotations " + names + " make it moment balanced")
                  : moment.message;
  design.message = design.message.empty() ? what : design.message + "; " + what;
}

}  // namespace bd::balance::planar
