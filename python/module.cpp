// The Python module balance_design._balance_design: studies loaded, built and run through the
// same code as the command line (studies/studies.hpp), the results as NumPy arrays and dicts,
// the program's errors as Python exceptions with its one-line messages. docs/python.md.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "studies/run/runner.hpp"
#include "studies/studies.hpp"
#include "studies/study/load_study.hpp"
#include "studies/study/study_yaml.hpp"

namespace bd::python {

namespace fs = std::filesystem;
using studies::RunResult;
using studies::Study;

py::dict series_dict(const core::Series& table) {
  py::dict out;
  const std::size_t rows = table.rows();
  for (std::size_t k = 0; k < table.width(); ++k) {
    py::array_t<double> column(static_cast<py::ssize_t>(rows));
    double* p = column.mutable_data();
    for (std::size_t i = 0; i < rows; ++i) p[i] = table.at(i, k);
    out[py::str(table.columns[k])] = std::move(column);
  }
  return out;
}

py::array_t<double> series_array(const core::Series& table) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(table.rows()), static_cast<py::ssize_t>(table.width())});
  std::copy(table.values.begin(), table.values.end(), out.mutable_data());
  return out;
}

py::object json_object(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

py::dict csv_columns(const std::string& text) {
  return py::module_::import("balance_design._tables").attr("csv_columns")(text);
}

namespace {

// a run and the study it ran, kept together (a result's views need both)
struct Run {
  std::shared_ptr<Study> study;
  RunResult result;
};
using RunPtr = std::shared_ptr<Run>;

// the balanced design's or the optimum's run within a Run
struct DesignRun {
  RunPtr run;
  bool optimized{};
  const studies::BalancedRun& balanced() const { return *run->result.balanced; }
  const studies::OptimizedRun& optimum() const { return *run->result.optimized; }
  core::Series table() const {
    if (optimized) {
      return optimum().is_planar ? optimum().planar.table
                                 : studies::timeseries_table(optimum().trajectory);
    }
    return balanced().is_planar ? balanced().planar.table
                                : studies::timeseries_table(balanced().trajectory);
  }
  const studies::MetricList& metric_list() const {
    return optimized ? optimum().metric_list : balanced().metric_list;
  }
  studies::RunStatus status() const { return optimized ? optimum().status() : balanced().status(); }
};

core::Series original_table(const Run& r) {
  return r.study->is_fourbar() ? studies::timeseries_table(r.result.trajectory)
                               : r.result.planar.table;
}

py::dict metrics_dict(const studies::MetricList& list) {
  py::dict out;
  for (const studies::MetricValue& m : list) out[py::str(m.name)] = m.value;
  return out;
}

std::shared_ptr<Study> shared(Study study) { return std::make_shared<Study>(std::move(study)); }

// the study of a run's balanced design or optimum, as Study objects to run on their own
std::shared_ptr<Study> design_study(const DesignRun& d) {
  const Study& s = *d.run->study;
  if (d.optimized) {
    return shared(d.optimum().is_planar
                      ? studies::planar_optimized_study(s, d.optimum().planar_result.design)
                      : studies::optimized_study(s, d.optimum().result.design));
  }
  if (!d.balanced().is_planar) return shared(studies::balanced_study(s));
  if (!d.balanced().design) return nullptr;
  return shared(studies::planar_balanced_study(s, d.balanced().design->linkage));
}

RunPtr compute(const std::shared_ptr<Study>& study, const std::optional<fs::path>& out_dir) {
  if (study->sweep) {
    throw InputError(study->name +
                     ": the study has a sweep section: Study.sweep(out_dir) runs it point by "
                     "point");
  }
  auto run = std::make_shared<Run>();
  run->study = study;
  py::gil_scoped_release unlocked;
  run->result = out_dir ? studies::run_study(*study, *out_dir) : studies::compute_study(*study);
  return run;
}

// one sweep: the Python callback sees a dict per row written; Ctrl-C or an exception in the
// callback stops the sweep as the program's SIGINT does (the points running finish and are
// written), then propagates
studies::SweepResult sweep(const Study& study, const fs::path& out_dir, const py::object& progress,
                           bool resume, int threads) {
  studies::SweepOptions options;
  options.resume = resume;
  options.threads = threads;
  std::atomic<bool> stop{false};
  options.stop = &stop;
  std::optional<py::error_already_set> failure;
  options.progress = [&](const studies::SweepProgress& p) {
    py::gil_scoped_acquire locked;
    if (failure) return;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!progress.is_none()) {
        using namespace pybind11::literals;
        progress(py::dict("done"_a = p.done, "points"_a = p.points, "resumed"_a = p.resumed,
                          "elapsed_s"_a = p.elapsed_s, "finished"_a = p.finished));
      }
    } catch (py::error_already_set& e) {
      failure.emplace(std::move(e));
      stop.store(true);
    }
  };
  studies::SweepResult result;
  {
    py::gil_scoped_release unlocked;
    result = studies::run_sweep(study, out_dir, options);
  }
  if (failure) throw std::move(*failure);
  return result;
}

void bind_errors(py::module_& m) {
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<studies::StudyError> study_error(m, "StudyError", input_error.ptr());
  py::register_exception<DynamicsFailure>(m, "DynamicsError", PyExc_RuntimeError);
  input_error.doc() =
      "A mistake in the input (a non-physical value, a wrong option): str(e) is the program's "
      "one-line message, e.g. 'coupler.mass must be > 0 kg, got -3'. A subclass of ValueError.";
  study_error.doc() =
      "A mistake in a study file or text: str(e) is 'FILE:LINE:COLUMN: message', the line the "
      "program prints; e.file, e.line, e.column (1-based, 0 when unknown) and e.message say it "
      "in parts. A subclass of InputError.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const studies::StudyError& e) {
      py::object exc = py::reinterpret_borrow<py::object>(study_error.ptr())(e.what());
      exc.attr("file") = e.file();
      exc.attr("line") = e.line();
      exc.attr("column") = e.column();
      exc.attr("message") = e.message();
      PyErr_SetObject(study_error.ptr(), exc.ptr());
    } catch (const InputError& e) {
      py::object exc = py::reinterpret_borrow<py::object>(input_error.ptr())(e.what());
      py::object field = py::none();
      if (e.field()) field = py::str(e.field()->field);
      exc.attr("field") = field;
      PyErr_SetObject(input_error.ptr(), exc.ptr());
    }
  });
}

void bind_results(py::module_& m) {
  py::class_<DesignRun>(m, "DesignRun",
                        "The balanced design's or the optimum's run within a Result: its samples, "
                        "metrics and status, and the design as a Study of its own.")
      .def_property_readonly(
          "timeseries", [](const DesignRun& d) { return series_dict(d.table()); },
          "dict column -> NumPy array: balanced-timeseries.csv or optimized-timeseries.csv")
      .def_property_readonly(
          "array", [](const DesignRun& d) { return series_array(d.table()); },
          "the samples as one 2-D array (rows x columns, in the order of `columns`)")
      .def_property_readonly(
          "columns", [](const DesignRun& d) { return d.table().columns; }, "the column names")
      .def_property_readonly(
          "metrics", [](const DesignRun& d) { return metrics_dict(d.metric_list()); },
          "dict metric -> value, in the metric table's order (summary.json's balanced_metrics "
          "or optimized_metrics)")
      .def_property_readonly(
          "status", [](const DesignRun& d) { return core::to_string(d.status().status); },
          "how its simulation ended: 'completed', 'singular', ...")
      .def_property_readonly(
          "message", [](const DesignRun& d) { return d.status().message; }, "why it ended so")
      .def_property_readonly(
          "method",
          [](const DesignRun& d) {
            const studies::MethodChoice& c = d.optimized ? d.optimum().method : d.balanced().method;
            return std::string(studies::to_string(c.method));
          },
          "the method its simulation used")
      .def_property_readonly("study", &design_study,
                             "the design as a Study (balanced.yaml or optimized.yaml's study), "
                             "to run or change on its own; None when it was not synthesised")
      .def_property_readonly(
          "yaml",
          [](const DesignRun& d) {
            const Study& s = *d.run->study;
            if (d.optimized) return studies::optimized_yaml(s, d.optimum());
            if (d.balanced().is_planar) {
              if (!d.balanced().design) throw InputError("no balanced design was synthesised");
              return studies::balanced_yaml(s, *d.balanced().design);
            }
            return studies::balanced_yaml(s);
          },
          "the text of balanced.yaml or optimized.yaml");

  py::class_<Run, std::shared_ptr<Run>>(
      m, "Result",
      "What a study's run computed: the samples, metrics and status of the original design, and "
      "with a balance or optimize section the second design (balanced, optimized). summary is "
      "summary.json as a dict; the arrays hold the doubles timeseries.csv prints.")
      .def_property_readonly(
          "study", [](const Run& r) { return r.study; }, "the Study that ran")
      .def_property_readonly(
          "timeseries", [](const Run& r) { return series_dict(original_table(r)); },
          "dict column -> NumPy array, the columns of timeseries.csv in order")
      .def_property_readonly(
          "array", [](const Run& r) { return series_array(original_table(r)); },
          "the samples as one 2-D array (rows x columns, in the order of `columns`)")
      .def_property_readonly(
          "columns", [](const Run& r) { return original_table(r).columns; },
          "the column names of timeseries.csv")
      .def_property_readonly(
          "metrics", [](const Run& r) { return metrics_dict(r.result.metric_list); },
          "dict metric -> value (summary.json's metrics), in the metric table's order")
      .def_property_readonly(
          "summary",
          [](const Run& r) { return json_object(studies::summary_json(*r.study, r.result)); },
          "summary.json as a dict: method and why, scene, status, metrics, and with a balance "
          "section the counterweights, balance conditions, balanced_metrics and reduction; with "
          "an optimize section the solver's end, variables, optimized_metrics; harmonics")
      .def_property_readonly(
          "status", [](const Run& r) { return core::to_string(r.result.status().status); },
          "how the original's simulation ended: 'completed', 'singular', ...")
      .def_property_readonly(
          "message", [](const Run& r) { return r.result.status().message; },
          "why it ended so (time and crank angle of a singular position)")
      .def_property_readonly(
          "ok", [](const Run& r) { return r.result.ok(); },
          "True when every simulation ran to the end and an optimize study found its optimum "
          "(the program's exit code 0)")
      .def_property_readonly(
          "stopped_early", [](const Run& r) { return r.result.stopped_early(); },
          "True when a simulation stopped early (the program's exit code 3)")
      .def_property_readonly(
          "method",
          [](const Run& r) { return std::string(studies::to_string(r.result.method.method)); },
          "the method used for the original design")
      .def_property_readonly(
          "method_reason", [](const Run& r) { return r.result.method.reason; },
          "why that method (what auto took, in words)")
      .def_property_readonly(
          "method_numerics", [](const Run& r) { return r.result.method.numerics; },
          "how that method computes: the integrator and how it keeps the joints together")
      .def_property_readonly(
          "warnings", [](const Run& r) { return r.result.warnings; },
          "what went wrong besides the run (a report page not written)")
      .def_property_readonly(
          "balanced",
          [](const std::shared_ptr<Run>& r) -> std::optional<DesignRun> {
            if (!r->result.balanced) return std::nullopt;
            return DesignRun{r, false};
          },
          "the balanced design's run (a balance section), else None")
      .def_property_readonly(
          "optimized",
          [](const std::shared_ptr<Run>& r) -> std::optional<DesignRun> {
            if (!r->result.optimized || !r->result.optimized->found()) return std::nullopt;
            return DesignRun{r, true};
          },
          "the optimum's run (an optimize section whose optimiser found a design), else None")
      .def_property_readonly(
          "comparison",
          [](const Run& r) -> py::object {
            if (!r.result.balanced && !(r.result.optimized && r.result.optimized->found())) {
              return py::none();
            }
            return csv_columns(studies::comparison_csv(*r.study, r.result));
          },
          "comparison.csv as columns: metric, before, after, ratio (NaN where before is 0); "
          "None without a second design")
      .def_property_readonly(
          "pareto",
          [](const Run& r) -> py::object {
            const bool front = r.result.optimized && r.result.optimized->found() &&
                               ((r.study->optimize && r.study->optimize->pareto) ||
                                (r.study->planar_optimize && r.study->planar_optimize->pareto));
            if (!front) return py::none();
            return csv_columns(studies::pareto_csv(*r.study, *r.result.optimized));
          },
          "pareto.csv as columns (epsilon, the two metrics, termination, verification_error, "
          "the design variables); None without optimize.pareto");
}

void bind_study(py::module_& m, py::class_<Study, std::shared_ptr<Study>>& cls) {
  cls.def_property_readonly(
         "name", [](const Study& s) { return s.name; }, "the study's name")
      .def_property_readonly(
          "source", [](const Study& s) { return s.source; },
          "the file or name it was read from (errors name it)")
      .def_property_readonly(
          "linkage_type", [](const Study& s) { return s.is_fourbar() ? "fourbar" : "planar"; },
          "'fourbar' or 'planar'")
      .def_property_readonly(
          "scene_type", [](const Study& s) { return studies::scene_type(s.scene); },
          "'free' or 'driven'")
      .def_property_readonly(
          "method", [](const Study& s) { return s.method_name(); },
          "the requested method ('auto', 'mass-matrix', ..., 'truss-dae')")
      .def_property_readonly(
          "has_balance",
          [](const Study& s) { return s.balance.has_value() || s.planar_balance.has_value(); },
          "True with a balance section")
      .def_property_readonly(
          "has_optimize", [](const Study& s) { return s.optimizes(); },
          "True with an optimize section")
      .def_property_readonly(
          "has_sweep", [](const Study& s) { return s.sweep.has_value(); },
          "True with a sweep section")
      .def_property_readonly(
          "yaml", [](const Study& s) { return studies::study_yaml(s, ""); },
          "the study written back as a study file: linkage, loads, scene, method and "
          "tolerance, numbers to the last digit (no balance, optimize or sweep section)")
      .def(
          "run",
          [](const std::shared_ptr<Study>& s, std::optional<fs::path> out_dir) {
            return compute(s, out_dir);
          },
          py::arg("out_dir") = py::none(),
          "Runs the study as `balance-design run` does and returns a Result: simulates its scene, "
          "and with a balance section synthesises and simulates the balanced design, with an "
          "optimize section solves for the optimum and simulates it.\n\n"
          "out_dir: when given, also writes the program's files there (timeseries.csv, "
          "summary.json, ..., report.html), the same bytes as the program writes.\n"
          "Raises InputError for an invalid scene or options. Releases the GIL while it runs.")
      .def(
          "sweep",
          [](const Study& s, const fs::path& out_dir, const py::object& progress, bool resume,
             int threads) {
            if (!s.sweep) throw InputError(s.name + ": the study has no sweep section");
            return sweep(s, out_dir, progress, resume, threads);
          },
          py::arg("out_dir"), py::arg("progress") = py::none(), py::arg("resume") = false,
          py::arg("threads") = 0,
          "Runs a study with a sweep section at every point, in parallel, into out_dir "
          "(sweep.csv, sweep.json, report.html), as `balance-design run` does, and returns a "
          "SweepResult; its `table` is sweep.csv as columns.\n\n"
          "progress: called as progress(dict) after every row written (keys done, points, "
          "resumed, elapsed_s, finished), on the calling thread. An exception raised in it, or "
          "Ctrl-C, stops the sweep once the points running are written, then propagates "
          "(run again with resume=True to compute the rest).\n"
          "threads: points in parallel (0: the study's sweep.threads, else one per core).\n"
          "Releases the GIL while the points run.")
      .def("__repr__", [](const Study& s) {
        return "<balance_design.Study '" + s.name +
               "': " + (s.is_fourbar() ? "fourbar" : "planar") + ", " +
               studies::scene_type(s.scene) + " scene>";
      });

  py::class_<studies::SweepResult>(m, "SweepResult", "What a sweep did and where its files are.")
      .def_readonly("points", &studies::SweepResult::points, "points in the design")
      .def_readonly("done", &studies::SweepResult::done, "rows in sweep.csv (resumed included)")
      .def_readonly("resumed", &studies::SweepResult::resumed, "rows kept from an earlier run")
      .def_readonly("failed", &studies::SweepResult::failed, "rows whose status is not ok")
      .def_readonly("interrupted", &studies::SweepResult::interrupted, "stopped before the end")
      .def_readonly("csv", &studies::SweepResult::csv, "path of sweep.csv")
      .def_readonly("summary", &studies::SweepResult::summary, "path of sweep.json")
      .def_readonly("warnings", &studies::SweepResult::warnings, "a report page not written")
      .def_property_readonly("complete", &studies::SweepResult::complete, "every point done")
      .def_property_readonly(
          "table",
          [](const studies::SweepResult& r) {
            return py::module_::import("balance_design._tables").attr("read_csv")(r.csv);
          },
          "sweep.csv as columns: point, the swept parameters, the metrics (float64 arrays, NaN "
          "where empty), status and message (lists of str)");
}

}  // namespace

}  // namespace bd::python

PYBIND11_MODULE(_balance_design, m) {
  namespace py = pybind11;
  using namespace bd::python;
  m.doc() =
      "balance-design's library: studies of planar linkages (shaking force and moment, "
      "balancing, optimisation), run as the program runs them. See docs/python.md.";
  bind_errors(m);
  py::class_<bd::studies::Study, std::shared_ptr<bd::studies::Study>> study(
      m, "Study",
      "A study: one linkage with its loads, one scene, and optionally a balance, optimize or "
      "sweep section (docs/study-format.md). Made by load_study(), parse_study() or "
      "study_from_dict(); never changed afterwards (a design is a new Study).");
  bind_results(m);
  bind_study(m, study);
  bind_instant(m, study);
  m.def(
      "load_study",
      [](const std::filesystem::path& path) {
        return std::make_shared<bd::studies::Study>(bd::studies::load_study(path.string()));
      },
      py::arg("path"),
      "Reads and checks the study file at `path` as the program does.\n"
      "Raises StudyError ('FILE:LINE:COLUMN: message', the program's line) on any mistake.");
  m.def(
      "parse_study",
      [](const std::string& text, const std::string& name) {
        return std::make_shared<bd::studies::Study>(bd::studies::parse_study(text, name));
      },
      py::arg("text"), py::arg("name") = "<string>",
      "Reads and checks a study from YAML text; `name` stands for the file in errors "
      "('<string>:LINE:COLUMN: message').\nRaises StudyError on any mistake.");
  m.attr("__version__") = BD_VERSION;
}
