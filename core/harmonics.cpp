#include "core/harmonics.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <unsupported/Eigen/FFT>

namespace bd::core {

namespace {

using Complex = std::complex<double>;

// the spectrum c_m = (1/N) Σ z_j e^{-2πi m j/N}
std::vector<Complex> spectrum(const std::vector<Complex>& z) {
  Eigen::FFT<double> fft;
  std::vector<Complex> c;
  fft.fwd(c, z);
  for (Complex& v : c) v /= static_cast<double>(z.size());
  return c;
}

// an angle in (-π, π]
double wrapped(double a) {
  a = std::remainder(a, 2 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2 * std::numbers::pi : a;
}

// an order at or below this fraction of the largest is round-off: its phase is noise, given as 0
constexpr double kRoundOff = 1e-11;

// the largest |c_m|
double largest(const std::vector<Complex>& c) {
  double m = 0;
  for (const Complex& v : c) m = std::max(m, std::abs(v));
  return m;
}

// the phase of c at the input angle: c e^{ik(θ-θ0)} = |c| e^{i(kθ + arg c - kθ0)}; 0 for an
// order that is round-off beside the largest, `scale`
double phase_of(const Complex& c, int k, double theta0, double scale) {
  return std::abs(c) > kRoundOff * scale ? wrapped(std::arg(c) - k * theta0) : 0.0;
}

int highest(std::size_t n, int max_order) {
  return std::min(max_order, static_cast<int>(n / 2) - 1);
}

}  // namespace

std::vector<Harmonic> harmonic_orders(std::span<const double> samples, double theta0,
                                      int max_order) {
  std::vector<Harmonic> out;
  if (samples.empty()) return out;
  const std::vector<Complex> c = spectrum(std::vector<Complex>(samples.begin(), samples.end()));
  const double scale = largest(c);
  out.push_back({0, c[0].real(), 0.0});
  for (int k = 1; k <= highest(samples.size(), max_order); ++k) {
    // q = Σ 2 Re(c_k e^{ik(θ-θ0)}) for a real q
    const Complex ck = c[static_cast<std::size_t>(k)];
    out.push_back({k, 2 * std::abs(ck), phase_of(ck, k, theta0, scale)});
  }
  return out;
}

std::vector<RotatingHarmonic> rotating_orders(std::span<const double> x, std::span<const double> y,
                                              double theta0, int max_order) {
  std::vector<RotatingHarmonic> out;
  const std::size_t n = std::min(x.size(), y.size());
  if (n == 0) return out;
  std::vector<Complex> z(n);
  for (std::size_t j = 0; j < n; ++j) z[j] = Complex(x[j], y[j]);
  const std::vector<Complex> c = spectrum(z);
  const double scale = largest(c);
  for (int k = 1; k <= highest(n, max_order); ++k) {
    // F = Σ c_m e^{im(θ-θ0)}: forward c_k; backward c_{-k} = c_{N-k}, whose term
    // |c_{-k}| e^{-i(kθ - kθ0 - arg c_{-k})} has the phase arg c_{-k} + kθ0
    const Complex f = c[static_cast<std::size_t>(k)];
    const Complex b = c[n - static_cast<std::size_t>(k)];
    const double back = std::abs(b) > kRoundOff * scale ? wrapped(std::arg(b) + k * theta0) : 0.0;
    out.push_back({k, std::abs(f), std::abs(b), phase_of(f, k, theta0, scale), back});
  }
  return out;
}

}  // namespace bd::core
