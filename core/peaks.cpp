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

// Three known values of f: the sampled local maximum (t, x) inside the bracket and its
// neighbours at the bracket's ends.
struct KnownPoints {
  double ta, xa, t, x, tb, xb;
};

// Brent's method (golden section with parabolic steps, as in Brent 1973, ch. 5) maximising f on
// [a, b] to the time tolerance `tol`; `best` is raised to every value it evaluates. With `known`
// (a, b its ends), the search starts from the samples instead of a golden-section point: x the
// sampled maximum, w and v its neighbours, and the first step is the vertex of their parabola
// (as if the step before had spanned the bracket), so no evaluation is spent where the samples
// already tell.
void brent_maximise(const QuantityAt& f, double a, double b, double tol, Peak& best,
                    const KnownPoints* known = nullptr) {
  constexpr double kGolden = 0.3819660112501051;  // (3 - sqrt 5) / 2
  auto g = [&](double t) {  // minimised: -f
    const double v = value_at(f, t);
    if (v > best.value) best = {v, t};
    return -v;
  };
  double x, w, v, fx, fw, fv;
  double d = 0.0, e = 0.0;
  if (known) {
    const bool a_better = known->xa >= known->xb;
    x = known->t;
    fx = -known->x;
    w = a_better ? known->ta : known->tb;
    fw = -(a_better ? known->xa : known->xb);
    v = a_better ? known->tb : known->ta;
    fv = -(a_better ? known->xb : known->xa);
    e = b - a;
    d = 0.5 * (b - a);
  } else {
    x = w = v = a + kGolden * (b - a);
    fx = fw = fv = g(x);
  }
  double last_change = std::numeric_limits<double>::infinity();  // of the last parabolic step
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
    // is about the value's remaining error (f''(x - x*)²/2), so a step that changes it by under
    // kPeakValueTolerance of its size, right after one under kPeakSettlingTolerance, leaves the
    // largest value found within about that of the peak (the time then good to about the square
    // root of it); the bracket need not close. Golden steps (a kink, a step far from the
    // parabola's) never end it.
    const double change =
        golden ? std::numeric_limits<double>::infinity()
               : (fu == fx ? 0.0 : std::abs(fu - fx) / std::abs(fx));
    if (change <= kPeakValueTolerance && last_change <= kPeakSettlingTolerance) break;
    last_change = change;
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
  double xa{}, x{}, xb{};  // the samples at a, inside (at t) and at b, where both ends are samples
  double t{};
  bool interior{};  // both neighbours known: the search starts from the three samples
};

}  // namespace

std::vector<double> step_instants(std::span<const double> t, std::span<const long> steps_to,
                                  double stop, long steps_at_stop) {
  std::vector<double> out;
  if (steps_to.size() != t.size()) return out;
  // m - 1 instants evenly between ta and tb, where the integrator took m steps
  const auto between = [&out](double ta, double tb, long steps) {
    const long m = std::min(steps, kMaxStepInstants + 1);
    for (long j = 1; j < m; ++j) {
      out.push_back(ta + (tb - ta) * static_cast<double>(j) / static_cast<double>(m));
    }
  };
  for (std::size_t i = 0; i + 1 < t.size(); ++i)
    between(t[i], t[i + 1], steps_to[i + 1] - steps_to[i]);
  if (!t.empty() && stop > t.back()) {
    between(t.back(), stop, steps_at_stop - steps_to.back());
    out.push_back(stop);
  }
  return out;
}

Peak resolved_peak(std::span<const double> t, std::span<const double> x, double period,
                   const QuantityAt& f) {
  const std::size_t n = std::min(t.size(), x.size());
  if (f && (n >= 2 || (n == 1 && period > 0)) && n < kMinPeakSamples) {
    // Too few samples for their local maxima to bracket every peak (a driven revolution at 5
    // samples can have its largest value between two samples neither of which is a local
    // maximum): the quantity is evaluated between them too, at least kMinPeakSamples points
    // over the motion, and the peak is resolved over those.
    const std::size_t per = (kMinPeakSamples + n - 1) / n;  // points per interval
    std::vector<double> tt, xx;
    auto interval = [&](double ta, double xa, double tb) {
      tt.push_back(ta);
      xx.push_back(xa);
      for (std::size_t j = 1; j < per; ++j) {
        const double tj = ta + (tb - ta) * static_cast<double>(j) / static_cast<double>(per);
        const double v = f(tj);
        if (std::isfinite(v)) {
          tt.push_back(tj);
          xx.push_back(v);
        }
      }
    };
    for (std::size_t i = 0; i + 1 < n; ++i) interval(t[i], x[i], t[i + 1]);
    if (period > 0) {
      interval(t[n - 1], x[n - 1], t[0] + period);
    } else {
      tt.push_back(t[n - 1]);
      xx.push_back(x[n - 1]);
    }
    if (tt.size() >= kMinPeakSamples) return resolved_peak(tt, xx, period, f);
  }
  Peak best{-std::numeric_limits<double>::infinity(), 0.0};
  if (n < 3 || !f) {
    for (std::size_t i = 0; i < n; ++i) {
      if (x[i] > best.value) best = {x[i], t[i]};
    }
    return n == 0 ? Peak{0.0, 0.0} : best;
  }
  const bool periodic = period > 0;
  // A sample no neighbour rises above is a candidate; a smooth peak between its neighbours rises
  // above it by at most about an eighth of the drop to the lower neighbour, so the whole drop is
  // a generous bound (at an open end, where one neighbour is missing, at least 1e-3 of the
  // value). A candidate whose bound does not exceed the largest sample cannot win: those below
  // the largest sample so far are left out at once, the rest once the largest is known (below).
  // The largest sample is found in the same pass.
  std::vector<Candidate> candidates;
  auto consider = [&](std::size_t i, bool has_a, double ta, double xa, bool has_b, double tb,
                      double xb) {
    if ((has_a && xa > x[i]) || (has_b && xb > x[i])) return;  // not a local maximum
    const double drop = x[i] - std::min(has_a ? xa : x[i], has_b ? xb : x[i]);
    double upper = x[i] + drop;
    if (!has_a || !has_b) upper = x[i] + std::max(drop, std::abs(x[i]) * 1e-3);
    if (!(upper > best.value)) return;
    candidates.push_back({upper, has_a ? ta : t[i], has_b ? tb : t[i], xa, x[i], xb, t[i],
                          has_a && has_b});
  };
  // the ends: neighbours across the period's end when periodic, none at an open end
  // (the first largest sample is an end or a sample no neighbour rises above)
  if (x[0] > best.value) best = {x[0], t[0]};
  consider(0, periodic, t[n - 1] - period, x[n - 1], true, t[1], x[1]);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (x[i - 1] > x[i] || x[i + 1] > x[i]) continue;  // the common case, decided at once
    if (x[i] > best.value) best = {x[i], t[i]};
    consider(i, true, t[i - 1], x[i - 1], true, t[i + 1], x[i + 1]);
  }
  if (x[n - 1] > best.value) best = {x[n - 1], t[n - 1]};
  consider(n - 1, true, t[n - 2], x[n - 2], periodic, t[0] + period, x[0]);
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& p, const Candidate& q) { return p.upper > q.upper; });
  constexpr std::size_t kMaxCandidates = 64;
  for (std::size_t k = 0; k < candidates.size() && k < kMaxCandidates; ++k) {
    const Candidate& c = candidates[k];
    // sorted: none of the rest can rise above the best (a quantity that is constant over its
    // samples, such as a free scene's drive effort of 0, has no candidate to refine)
    if (c.upper <= best.value) break;
    if (!(c.b > c.a)) continue;
    const KnownPoints known{c.a, c.xa, c.t, c.x, c.b, c.xb};
    brent_maximise(f, c.a, c.b, kPeakTimeTolerance * (c.b - c.a), best,
                   c.interior && c.t > c.a && c.t < c.b ? &known : nullptr);
  }
  // a periodic time from the bracket across the end, back into [t0, t0 + period)
  if (periodic && best.t < t[0]) best.t += period;
  if (periodic && best.t >= t[0] + period) best.t -= period;
  return best;
}

}  // namespace bd::core
