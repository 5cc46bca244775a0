#include "core/peaks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace bd::core {

namespace {

// f where it can be evaluated, -inf where not (so a failed instant never wins)
double value_at(const QuantityAt& f, double t) {
  const double v = f(t);
  return std::isnan(v) ? -std::numeric_limits<double>::infinity() : v;
}

// Brent's method (golden section with parabolic steps, as in Brent 1973, ch. 5) maximising f on
// [a, b] to the time tolerance `tol`; `best` is raised to every value it evaluates
void brent_maximise(const QuantityAt& f, double a, double b, double tol, Peak& best) {
  constexpr double kGolden = 0.3819660112501051;  // (3 - sqrt 5) / 2
  auto g = [&](double t) {  // minimised: -f
    const double v = value_at(f, t);
    if (v > best.value) best = {v, t};
    return -v;
  };
  double x = a + kGolden * (b - a), w = x, v = x;
  double fx = g(x), fw = fx, fv = fx;
  double d = 0.0, e = 0.0;
  int quiet_steps = 0;
  for (int iter = 0; iter < 200; ++iter) {
    const double m = 0.5 * (a + b);
    const double tol1 = tol + 1e-15 * std::abs(x), tol2 = 2 * tol1;
    if (std::abs(x - m) <= tol2 - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol1 && std::isfinite(fx) && std::isfinite(fw) && std::isfinite(fv)) {
      // a parabola through x, w, v
      double r = (x - w) * (fx - fv), q = (x - v) * (fx - fw), p = (x - v) * q - (x - w) * r;
      q = 2 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      const double e_prev = e;
      e = d;
      if (std::abs(p) < std::abs(0.5 * q * e_prev) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = x < m ? tol1 : -tol1;
        golden = false;
      }
    }
    if (golden) {
      e = (x < m ? b : a) - x;
      d = kGolden * e;
    }
    const double u = std::abs(d) >= tol1 ? x + d : x + (d > 0 ? tol1 : -tol1);
    const double fu = g(u);
    // the value is what is wanted: near a smooth maximum, a parabolic step's change of the value
    // is about the value's remaining error (f''(x - x*)²/2), so two steps in a row that change
    // it by under kPeakValueTolerance of its size leave the largest value found within about
    // that of the peak (the time then good to about the square root of it); the bracket need not
    // close. Golden steps (a kink, a step far from the parabola's) never stop it.
    if (!golden && std::abs(fu - fx) <= kPeakValueTolerance * std::abs(fx)) {
      if (++quiet_steps >= 2) break;
    } else {
      quiet_steps = 0;
    }
    if (fu <= fx) {
      (u < x ? b : a) = x;
      v = w;
      fv = fw;
      w = x;
      fw = fx;
      x = u;
      fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w;
        fv = fw;
        w = u;
        fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u;
        fv = fu;
      }
    }
  }
}

struct Candidate {
  double upper{};  // a generous bound of the peak within the bracket
  double a{}, b{};  // the bracket [s]
};

}  // namespace

Peak resolved_peak(std::span<const double> t, std::span<const double> x, double period,
                   const QuantityAt& f) {
  const std::size_t n = std::min(t.size(), x.size());
  Peak best{-std::numeric_limits<double>::infinity(), 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    if (x[i] > best.value) best = {x[i], t[i]};
  }
  if (n == 0) return {0.0, 0.0};
  if (n < 3 || !f) return best;
  const bool periodic = period > 0;
  // the neighbours of sample i (across the period's end when periodic), or none at an open end
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < n; ++i) {
    const bool first = i == 0, last = i + 1 == n;
    double ta = 0, tb = 0, xa = 0, xb = 0;
    bool has_a = true, has_b = true;
    if (first) {
      has_a = periodic;
      if (periodic) {
        ta = t[n - 1] - period;
        xa = x[n - 1];
      }
    } else {
      ta = t[i - 1];
      xa = x[i - 1];
    }
    if (last) {
      has_b = periodic;
      if (periodic) {
        tb = t[0] + period;
        xb = x[0];
      }
    } else {
      tb = t[i + 1];
      xb = x[i + 1];
    }
    if ((has_a && xa > x[i]) || (has_b && xb > x[i])) continue;  // not a local maximum
    // a smooth peak between the neighbours rises above x[i] by at most about an eighth of the
    // drop to the lower neighbour; the whole drop is a generous bound
    const double drop = x[i] - std::min(has_a ? xa : x[i], has_b ? xb : x[i]);
    double upper = x[i] + drop;
    if (!has_a || !has_b) upper = x[i] + std::max(drop, std::abs(x[i]) * 1e-3);
    candidates.push_back({upper, has_a ? ta : t[i], has_b ? tb : t[i]});
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& p, const Candidate& q) { return p.upper > q.upper; });
  constexpr std::size_t kMaxCandidates = 64;
  for (std::size_t k = 0; k < candidates.size() && k < kMaxCandidates; ++k) {
    const Candidate& c = candidates[k];
    // sorted: none of the rest can rise above the best (a quantity that is constant over its
    // samples, such as a free scene's drive effort of 0, has no candidate to refine)
    if (c.upper <= best.value) break;
    if (!(c.b > c.a)) continue;
    brent_maximise(f, c.a, c.b, kPeakTimeTolerance * (c.b - c.a), best);
  }
  // a periodic time from the bracket across the end, back into [t0, t0 + period)
  if (periodic && best.t < t[0]) best.t += period;
  if (periodic && best.t >= t[0] + period) best.t -= period;
  return best;
}

}  // namespace bd::core
