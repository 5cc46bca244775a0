#include "studies/run/harmonics.hpp"

#include <cstddef>
#include <variant>

#include "core/number_text.hpp"

namespace bd::studies {

namespace {

// the first revolution's samples, in the order of the input's angle increasing (a negative speed
// takes them backwards from the first)
std::vector<double> revolution(const std::vector<double>& values, std::size_t n, double speed) {
  std::vector<double> out(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n));
  if (speed < 0) {
    for (std::size_t m = 1; m < n; ++m) out[m] = values[n - m];
  }
  return out;
}

Harmonics analysed(std::string input, double speed, double theta0, std::size_t n,
                   const std::vector<double>& fx, const std::vector<double>& fy,
                   const std::vector<double>& msh, const std::vector<double>& tau) {
  Harmonics h{std::move(input), speed, static_cast<int>(n), {}};
  const std::vector<double> x = revolution(fx, n, speed), y = revolution(fy, n, speed),
                            m = revolution(msh, n, speed), d = revolution(tau, n, speed);
  const std::vector<core::Harmonic> hx = core::harmonic_orders(x, theta0, kHarmonicOrders);
  const std::vector<core::Harmonic> hy = core::harmonic_orders(y, theta0, kHarmonicOrders);
  const std::vector<core::Harmonic> hm = core::harmonic_orders(m, theta0, kHarmonicOrders);
  const std::vector<core::Harmonic> ht = core::harmonic_orders(d, theta0, kHarmonicOrders);
  const std::vector<core::RotatingHarmonic> hr =
      core::rotating_orders(x, y, theta0, kHarmonicOrders);
  for (std::size_t k = 0; k < hx.size(); ++k) {
    HarmonicOrder o{static_cast<int>(k), hx[k], hy[k], hm[k], ht[k], {}};
    if (k > 0) o.Fsh = hr[k - 1];
    h.orders.push_back(o);
  }
  return h;
}

std::optional<Harmonics> fourbar_harmonics(const core::DrivenScene& scene,
                                           const core::Trajectory& t) {
  const std::size_t n = static_cast<std::size_t>(scene.samples);
  if (n < 4 || t.samples.size() < n) return std::nullopt;
  std::vector<double> fx, fy, msh, tau;
  for (std::size_t i = 0; i < n; ++i) {
    fx.push_back(t.samples[i].Fsh_inertial.x());
    fy.push_back(t.samples[i].Fsh_inertial.y());
    msh.push_back(t.samples[i].Msh_inertial);
    tau.push_back(t.samples[i].tau);
  }
  return analysed("crank", scene.omega1, scene.theta1, n, fx, fy, msh, tau);
}

std::optional<Harmonics> planar_harmonics(const core::planar::Linkage& l,
                                          const core::planar::DrivenScene& scene,
                                          const core::planar::Trajectory& t) {
  if (scene.duration > 0) return std::nullopt;
  int moving = -1;
  for (std::size_t k = 0; k < scene.speeds.size(); ++k) {
    if (scene.speeds[k] == 0) continue;
    if (moving >= 0) return std::nullopt;  // two inputs moving: not one period in general
    moving = static_cast<int>(k);
  }
  if (moving < 0) return std::nullopt;
  const core::planar::Input& input = l.inputs[static_cast<std::size_t>(moving)];
  if (input.kind != core::planar::Input::Kind::kAngle) return std::nullopt;
  const std::size_t n = static_cast<std::size_t>(scene.samples);
  if (n < 4 || t.table.rows() < n) return std::nullopt;
  const std::string link = l.links[static_cast<std::size_t>(input.link)].name;
  const double theta0 = t.table.column_values("theta_" + link).front();
  return analysed(input.name, scene.speeds[static_cast<std::size_t>(moving)], theta0, n,
                  t.table.column_values("Fshx_inertial"), t.table.column_values("Fshy_inertial"),
                  t.table.column_values("Msh_inertial"),
                  t.table.column_values(l.inputs.size() == 1 ? "tau" : "tau_" + input.name));
}

}  // namespace

std::optional<Harmonics> harmonics(const Study& study, const core::Trajectory& fourbar,
                                   const core::planar::Trajectory& planar) {
  if (const auto* s = std::get_if<core::DrivenScene>(&study.scene)) {
    return fourbar_harmonics(*s, fourbar);
  }
  if (const auto* s = std::get_if<core::planar::DrivenScene>(&study.scene)) {
    return planar_harmonics(study.planar(), *s, planar);
  }
  return std::nullopt;
}

std::string harmonics_rows(const std::string& design, const Harmonics& h) {
  std::string text;
  for (const HarmonicOrder& o : h.orders) {
    text += design + "," + std::to_string(o.order);
    for (double v : {o.Fshx.amplitude, o.Fshx.phase, o.Fshy.amplitude, o.Fshy.phase, o.Fsh.forward,
                     o.Fsh.forward_phase, o.Fsh.backward, o.Fsh.backward_phase, o.Msh.amplitude,
                     o.Msh.phase, o.tau.amplitude, o.tau.phase}) {
      text += "," + text::exact(v);
    }
    text += "\n";
  }
  return text;
}

}  // namespace bd::studies
