#pragma once
/// A table of samples: named columns, one row per instant, stored row by row. What a simulation
/// of any linkage type hands to the files, metrics and reports: they read it by column name.
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bd::core {

struct Series {
  std::vector<std::string> columns;
  std::vector<double> values;  // row-major: rows() x columns.size()

  std::size_t width() const { return columns.size(); }
  std::size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
  double at(std::size_t row, std::size_t column) const { return values[row * width() + column]; }
  std::span<const double> row(std::size_t i) const {
    return {values.data() + i * width(), width()};
  }
  /// The index of the column named `name`, or -1.
  int column(std::string_view name) const {
    for (std::size_t k = 0; k < columns.size(); ++k) {
      if (columns[k] == name) return static_cast<int>(k);
    }
    return -1;
  }
  /// The column named `name` as a vector (empty when there is none).
  std::vector<double> column_values(std::string_view name) const {
    std::vector<double> out;
    const int c = column(name);
    if (c < 0) return out;
    out.reserve(rows());
    for (std::size_t i = 0; i < rows(); ++i) out.push_back(at(i, static_cast<std::size_t>(c)));
    return out;
  }
};

}  // namespace bd::core
