#include "core/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace bd::core {

Metrics metrics(const Trajectory& trajectory) {
  Metrics m;
  const auto& samples = trajectory.samples;
  if (samples.empty()) return m;

  // sums of squares for the RMS, running maxima of the magnitudes
  double Fsh_sq = 0.0, Msh_sq = 0.0, tau_sq = 0.0, RA0_sq = 0.0, RA3_sq = 0.0;
  for (const DynamicsSample& s : samples) {
    const double Fsh = s.Fsh.norm(), Msh = std::abs(s.Msh), tau = std::abs(s.tau);
    const double RA0 = s.RA0.norm(), RA3 = s.RA3.norm();
    Fsh_sq += Fsh * Fsh;
    RA0_sq += RA0 * RA0;
    RA3_sq += RA3 * RA3;
    Msh_sq += Msh * Msh;
    tau_sq += tau * tau;
    m.Fsh_max = std::max(m.Fsh_max, Fsh);
    m.Msh_max = std::max(m.Msh_max, Msh);
    m.tau_max = std::max(m.tau_max, tau);
    m.RA0_max = std::max(m.RA0_max, RA0);
    m.RA3_max = std::max(m.RA3_max, RA3);
  }

  // RMS over samples
  const double n = static_cast<double>(samples.size());
  m.Fsh_rms = std::sqrt(Fsh_sq / n);
  m.Msh_rms = std::sqrt(Msh_sq / n);
  m.tau_rms = std::sqrt(tau_sq / n);
  m.RA0_rms = std::sqrt(RA0_sq / n);
  m.RA3_rms = std::sqrt(RA3_sq / n);
  return m;
}

}  // namespace bd::core
