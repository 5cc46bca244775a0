#pragma once
// Shared by the two translation units of the Python module _balance_design (python/module.cpp:
// studies, runs, sweeps, errors; python/instant.cpp: the core at one instant, the balance and
// optimise steps).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "core/series.hpp"
#include "studies/study/study.hpp"

namespace bd::python {

namespace py = pybind11;

/// A study as Python holds it: shared, never changed after loading (a design is a new Study).
using StudyPtr = std::shared_ptr<const studies::Study>;

/// What a dynamics call at one instant could not do (a dead centre, an assembly that does not
/// close): raised as balance_design.DynamicsError with the core's one-line message.
struct DynamicsFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A table's columns as a dict of NumPy arrays (column name -> 1-D float64 array), in order.
py::dict series_dict(const core::Series& table);
/// A table as one 2-D float64 array, rows by columns.
py::array_t<double> series_array(const core::Series& table);
/// The Python object of a JSON text (json.loads): numbers read back to the same doubles.
py::object json_object(const std::string& text);
/// A CSV text with a header (the program's comparison.csv, pareto.csv, sweep.csv) as a dict of
/// columns: float64 arrays where every field is a number or empty (NaN), else lists of str.
py::dict csv_columns(const std::string& text);

/// The core at one instant, and the balance and optimise steps, as methods of Study.
void bind_instant(py::module_& m, py::class_<studies::Study, std::shared_ptr<studies::Study>>& cls);

}  // namespace bd::python
