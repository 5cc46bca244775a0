#pragma once
/// Internal to optimize/: where a design's peaks lie among a program's instants, for the lean
/// program of the exchange rounds (peak_exchange.hpp) and the programs that list them
/// (Nlp::peak_instants(), planar::PlanarNlp::peak_instants()).
#include <algorithm>
#include <cstddef>
#include <vector>

namespace bd::optimize::detail {

/// Of the program's instants `at` (the samples, the first `samples` of them, then the added ones)
/// and the magnitudes `v` of one peak quantity there at a design, appends to `out` (each instant
/// once) the added instants at which v has a local maximum over the instants in the order of
/// `at` within `within` of the largest v, and the added instants next to them on either side:
/// three instants per peak of the design, where a grid of added instants has many around it. The
/// neighbours hold the peak in place: with its own instant alone, a solve could move the peak
/// off it (to second order in the design's change) and gain by that.
inline void add_local_maxima(const std::vector<double>& at, const std::vector<double>& v,
                             std::size_t samples, double within, std::vector<double>& out) {
  if (v.empty()) return;
  std::vector<std::size_t> order(at.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return at[a] < at[b]; });
  const double top = *std::max_element(v.begin(), v.end());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    if (i < samples || v[i] < top - within) continue;
    if (k > 0 && v[order[k - 1]] > v[i]) continue;
    if (k + 1 < order.size() && v[order[k + 1]] > v[i]) continue;
    for (std::size_t j = k > 0 ? k - 1 : k; j <= k + 1 && j < order.size(); ++j) {
      const double a = at[order[j]];
      if (order[j] >= samples && std::find(out.begin(), out.end(), a) == out.end())
        out.push_back(a);
    }
  }
}

}  // namespace bd::optimize::detail
