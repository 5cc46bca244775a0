// Assembly, driven scenes (inverse dynamics along prescribed inputs) and point motions.
//
// Driven scene at time t: the inputs are held at rate * (t - t0), so all n constraint rows
// (mechanism and inputs) form a square system J. Positions by Newton (continued from the
// previous sample), then
//   J q'  = (0, ..., 0, rates)             (the input rows' c_t = -rate)
//   J q'' = gamma                          (constant rates: no input acceleration)
//   J^T lambda = M q'' - Q                 (Newton–Euler of every body: M q'' = Q + J^T lambda)
// where the last ndof multipliers are the drive efforts.
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "tests/reference/planar/solve.hpp"

namespace bd::referee {

using detail::Index;
using detail::Real;
using detail::VecX;

namespace {

std::string at_time(double t) {
  std::ostringstream os;
  os << std::setprecision(12) << "at t = " << t << " s";
  return os.str();
}

VecX to_vector(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Index>(v.size())).cast<Real>();
}

void check_size(const detail::Model& model, const std::vector<double>& v, const char* what) {
  if (static_cast<Index>(v.size()) != model.ndof())
    throw std::domain_error(std::string("bd::referee: ") + what + " needs one value per input");
}

}  // namespace

std::vector<Pose> assemble(const Mechanism& mechanism, const std::vector<double>& input_values) {
  const detail::Model model = detail::compile(mechanism);
  check_size(model, input_values, "assemble");
  VecX q = detail::described_q(model);
  detail::continue_loop(model, VecX::Zero(model.ndof()), to_vector(input_values), q, "assemble");
  std::vector<Pose> poses;
  for (int i = 0; i < model.nb; ++i)
    poses.push_back({detail::dbl(q.segment<2>(3 * i)), static_cast<double>(q[3 * i + 2])});
  return poses;
}

std::vector<Sample> driven(const Mechanism& mechanism, const std::vector<double>& input_rates,
                           double t0, const std::vector<double>& times) {
  const detail::Model model = detail::compile(mechanism);
  check_size(model, input_rates, "driven");
  const VecX rates = to_vector(input_rates);
  const VecX mass = detail::mass_diagonal(model);
  VecX q = detail::described_q(model);
  VecX previous = VecX::Zero(model.ndof());
  std::vector<Sample> out;
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (i > 0 && times[i] < times[i - 1])
      throw std::domain_error("bd::referee: driven: sample times must ascend");
    detail::State s;
    s.t = times[i];
    const VecX values = rates * (Real(times[i]) - Real(t0));
    const auto f = detail::continue_loop(model, previous, values, q, "driven " + at_time(times[i]));
    previous = values;
    VecX rhs = VecX::Zero(model.n());
    rhs.tail(model.ndof()) = rates;
    s.q = q;
    s.qd = f.solve(rhs);
    s.qdd = f.solve(detail::gamma(model, s.q, s.qd));
    const VecX Q = detail::applied_forces(model, mechanism, s.t, s.q, s.qd);
    s.lambda = f.solve_transposed(mass.cwiseProduct(s.qdd) - Q);
    out.push_back(detail::make_sample(model, mechanism, s));
  }
  return out;
}

PointMotion point_motion(const Mechanism& mechanism, const Sample& sample, int body,
                         const Vec2& described_point) {
  if (body == kGround) return {described_point, {0, 0}, {0, 0}};
  const BodyState& b = sample.bodies.at(static_cast<std::size_t>(body));
  const Vec2 s = described_point - merged(mechanism.bodies[body]).com;
  const double c = std::cos(b.angle), sn = std::sin(b.angle);
  const Vec2 rho{c * s.x() - sn * s.y(), sn * s.x() + c * s.y()}, rho_perp{-rho.y(), rho.x()};
  PointMotion m;
  m.p = b.com + rho;
  m.v = b.velocity + b.omega * rho_perp;
  m.a = b.acceleration + b.alpha * rho_perp - b.omega * b.omega * rho;
  return m;
}

}  // namespace bd::referee
