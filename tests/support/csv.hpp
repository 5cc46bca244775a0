#pragma once
// Test support: reading the numbers of a CSV file and comparing two of them column by column.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace bd::testing {

/// The numbers of a CSV file below its header line, row by row.
inline std::vector<std::vector<double>> read_csv_numbers(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

/// Two CSV files with the same shape whose entries agree to `relative` times the largest
/// magnitude of their column in `b` (at least 1).
inline void expect_same_numbers(const std::filesystem::path& a, const std::filesystem::path& b,
                                double relative) {
  const auto x = read_csv_numbers(a), y = read_csv_numbers(b);
  ASSERT_EQ(x.size(), y.size()) << a << " vs " << b;
  ASSERT_FALSE(y.empty()) << b;
  std::vector<double> scale(y.front().size(), 1.0);
  for (const auto& row : y) {
    for (std::size_t c = 0; c < row.size() && c < scale.size(); ++c) {
      scale[c] = std::max(scale[c], std::abs(row[c]));
    }
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(x[i].size(), y[i].size()) << "row " << i;
    for (std::size_t c = 0; c < x[i].size(); ++c) {
      EXPECT_NEAR(x[i][c], y[i][c], relative * scale[c]) << "row " << i << ", column " << c;
    }
  }
}

}  // namespace bd::testing
