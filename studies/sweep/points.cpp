// The points of a sweep design and the study at each point. run_sweep() and the CSV columns are
// in sweep_runner.cpp, the report in sweep_report.cpp.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "studies/study/load_study.hpp"
#include "studies/study/load_study_internal.hpp"
#include "studies/sweep/sweep.hpp"

namespace bd::studies {

const char* to_string(SweepDesign design) {
  switch (design) {
    case SweepDesign::kGrid:
      return "grid";
    case SweepDesign::kRandom:
      return "random";
    case SweepDesign::kLatinHypercube:
      return "lhs";
  }
  return "grid";
}

namespace {

// The generator behind random and LHS designs, written out so that a seed gives the same
// points with every compiler and standard library (std::uniform_real_distribution and
// std::shuffle are implementation-defined): xoshiro256** (Blackman & Vigna 2018), its state
// filled by splitmix64 from the seed.
class Generator {
 public:
  explicit Generator(std::uint64_t seed) {
    std::uint64_t x = seed;
    for (std::uint64_t& w : s_) w = splitmix64(x);
  }

  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  // uniform in [0, 1): the top 53 bits, each double k 2^-53 equally likely
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  // uniform in {0, ..., m - 1}, m >= 1, without modulo bias: draws below 2^64 mod m are
  // rejected, so the accepted range is a whole number of copies of 0..m-1
  std::uint64_t below(std::uint64_t m) {
    const std::uint64_t threshold = (0 - m) % m;  // 2^64 mod m
    while (true) {
      const std::uint64_t x = next();
      if (x >= threshold) return x % m;
    }
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  std::uint64_t s_[4];
};

// The value at fraction u in [0, 1] of [lo, hi]: linear, or geometric (evenly in log, then
// 0 < lo). Both ends exact.
double at_fraction(double lo, double hi, double u, bool log_scale) {
  if (u <= 0) return lo;
  if (u >= 1) return hi;
  if (!log_scale) return lo + (hi - lo) * u;
  const double a = std::log(lo);
  return std::exp(a + (std::log(hi) - a) * u);
}

// u in [0, 1) mapped into [lo, hi): rounding can land on hi (or, in log, a hair outside), so
// the result is pulled back inside
double draw_in(double lo, double hi, double u, bool log_scale) {
  const double v = at_fraction(lo, hi, u, log_scale);
  if (v < lo) return lo;
  if (v >= hi) return std::nextafter(hi, lo);
  return v;
}

}  // namespace

int sweep_size(const SweepRequest& request) {
  if (request.parameters.empty()) return 0;
  if (request.design != SweepDesign::kGrid) return std::max(request.points, 0);
  std::size_t n = 1;
  for (const SweepParameter& p : request.parameters) n *= p.values.size();
  return static_cast<int>(n);
}

std::vector<std::vector<double>> sweep_points(const SweepRequest& request) {
  PointCursor cursor(request);
  std::vector<std::vector<double>> points;
  points.reserve(static_cast<std::size_t>(cursor.size()));
  for (int i = 0; i < cursor.size(); ++i) {
    const std::span<const double> v = cursor.at(i);
    points.emplace_back(v.begin(), v.end());
  }
  return points;
}

// Where the design's points come from. Grid: the Cartesian product, like nested loops with the
// first parameter outermost (an odometer whose last digit turns fastest). Random: point by
// point, parameter by parameter, one uniform draw each, from one generator. Latin hypercube:
// parameter by parameter, a random permutation of the strata 0..n-1 (Fisher-Yates, from the
// last position down), then point by point one uniform draw inside the point's stratum
// [e_s, e_{s+1}), e_s the value at fraction s/n of [from, to]; the generator after each
// parameter's permutation is kept with the permutation, and skips the n draws that follow.
struct PointCursor::State {
  const SweepRequest* request{};
  std::size_t n{}, np{};
  std::vector<double> values;  // the point last asked for
  std::vector<std::size_t> radix;           // grid: each parameter's count
  std::vector<Generator> generators;        // random: one; LHS: one per parameter
  std::vector<std::vector<std::uint32_t>> strata;  // LHS: per parameter, point -> stratum
  std::size_t next{};  // random, LHS: the point whose draws come next
};

PointCursor::PointCursor(const SweepRequest& request) : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.request = &request;
  st.np = request.parameters.size();
  st.values.resize(st.np);
  if (st.np == 0) return;
  st.n = static_cast<std::size_t>(sweep_size(request));
  if (request.design == SweepDesign::kGrid) {
    for (const SweepParameter& p : request.parameters) st.radix.push_back(p.values.size());
    return;
  }
  Generator g(request.seed);
  if (request.design == SweepDesign::kRandom) {
    st.generators.push_back(g);
    return;
  }
  // parameter by parameter: the permutation's draws, then the n uniform ones skipped
  std::vector<std::uint32_t> stratum(st.n);
  for (std::size_t j = 0; j < st.np; ++j) {
    for (std::size_t i = 0; i < st.n; ++i) stratum[i] = static_cast<std::uint32_t>(i);
    for (std::size_t i = st.n; i-- > 1;) std::swap(stratum[i], stratum[g.below(i + 1)]);
    st.generators.push_back(g);
    st.strata.push_back(stratum);
    for (std::size_t i = 0; i < st.n; ++i) g.next();
  }
}

PointCursor::PointCursor(PointCursor&&) noexcept = default;
PointCursor& PointCursor::operator=(PointCursor&&) noexcept = default;
PointCursor::~PointCursor() = default;

int PointCursor::size() const { return static_cast<int>(state_->n); }

std::span<const double> PointCursor::at(int index) {
  State& st = *state_;
  const SweepRequest& request = *st.request;
  const auto i = static_cast<std::size_t>(index);
  if (request.design == SweepDesign::kGrid) {
    // the odometer's digits of i, the last parameter turning fastest
    std::size_t rest = i;
    for (std::size_t j = st.np; j-- > 0;) {
      st.values[j] = request.parameters[j].values[rest % st.radix[j]];
      rest /= st.radix[j];
    }
    return st.values;
  }
  if (request.design == SweepDesign::kRandom) {
    Generator& g = st.generators[0];
    for (; st.next < i; ++st.next) {
      for (std::size_t j = 0; j < st.np; ++j) g.next();
    }
    for (std::size_t j = 0; j < st.np; ++j) {
      const SweepParameter& p = request.parameters[j];
      st.values[j] = draw_in(p.from, p.to, g.uniform(), p.log_scale);
    }
    st.next = i + 1;
    return st.values;
  }
  const double dn = static_cast<double>(st.n);
  for (std::size_t j = 0; j < st.np; ++j) {
    Generator& g = st.generators[j];
    for (std::size_t k = st.next; k < i; ++k) g.next();
    const SweepParameter& p = request.parameters[j];
    const double s = static_cast<double>(st.strata[j][i]);
    const double lo = at_fraction(p.from, p.to, s / dn, p.log_scale);
    const double hi = at_fraction(p.from, p.to, (s + 1) / dn, p.log_scale);
    st.values[j] = draw_in(lo, hi, g.uniform(), p.log_scale);
  }
  st.next = i + 1;
  return st.values;
}

namespace {

// A sweep's study file as a YAML tree without its sweep section, with the node of each swept
// path. Loading the text is most of a point's set-up (yaml-cpp takes about 0.4 ms for the
// example's 3 kB, comments included), while setting a few scalars in place costs next to nothing
// and keeps each node's mark, so the tree is loaded once per thread and reused point after point.
struct PreparedTree {
  std::string text;                // the study text it was loaded from
  std::vector<std::string> paths;  // the swept paths, in order
  YAML::Node root;
  std::vector<YAML::Node> targets;  // the node at each path
};

// this thread's tree for `sweep` (trees are never shared between threads: yaml-cpp nodes are
// not safe to write from one thread while another reads them)
PreparedTree& prepared_tree(const SweepRequest& sweep, const std::string& source) {
  thread_local std::unique_ptr<PreparedTree> cache;
  auto same_paths = [&](const PreparedTree& t) {
    if (t.paths.size() != sweep.parameters.size()) return false;
    for (std::size_t j = 0; j < t.paths.size(); ++j) {
      if (t.paths[j] != sweep.parameters[j].path) return false;
    }
    return true;
  };
  if (cache && cache->text == sweep.study_text && same_paths(*cache)) return *cache;

  cache.reset();
  auto t = std::make_unique<PreparedTree>();
  t->text = sweep.study_text;
  try {
    t->root.reset(YAML::Load(t->text));
  } catch (const YAML::Exception& e) {
    // the text loaded once already; only a request built in code can get here
    throw StudyError(source, e.mark.is_null() ? 0 : e.mark.line + 1, e.mark.column + 1, e.msg);
  }
  for (const SweepParameter& p : sweep.parameters) {
    const auto steps = internal::parse_path(p.path);
    if (!steps) throw std::invalid_argument("point_study: '" + p.path + "' is not a path");
    t->paths.push_back(p.path);
    t->targets.push_back(internal::node_at(t->root, *steps));
  }
  t->root.remove("sweep");
  cache = std::move(t);
  return *cache;
}

}  // namespace

Study point_study(const Study& base, std::span<const double> values) {
  if (!base.sweep || values.size() != base.sweep->parameters.size()) {
    throw std::invalid_argument("point_study: the study has no sweep, or " +
                                std::to_string(values.size()) +
                                " values were given for its parameters");
  }
  PreparedTree& tree = prepared_tree(*base.sweep, base.source);
  for (std::size_t j = 0; j < values.size(); ++j) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", values[j]);
    // set in place: the node keeps its mark, so an invalid value is reported at its place
    tree.targets[j] = std::string(text);
  }
  // the parser only reads the tree
  Study study = internal::parse_study_tree(tree.root, base.source);
  study.name = base.name;
  return study;
}

}  // namespace bd::studies
