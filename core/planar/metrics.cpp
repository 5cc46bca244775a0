#include "core/planar/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <span>
#include <utility>

#include "core/detail/known_instants.hpp"
#include "core/detail/sensitivity.hpp"
#include "core/planar/system.hpp"

namespace bd::core::planar {

std::vector<ColumnMetric> metric_table(const Model& model) {
  const Linkage& l = model.linkage();
  std::vector<ColumnMetric> t;
  auto both = [&](const std::string& symbol, const char* unit, const std::string& what,
                  std::vector<std::string> columns) {
    t.push_back({symbol + "_rms", unit, "RMS of " + what, Statistic::kRms, columns});
    t.push_back({symbol + "_max", unit, "peak of " + what, Statistic::kMax, columns});
  };
  both("Fsh", "N", "the inertial shaking force |Fsh|", {"Fshx_inertial", "Fshy_inertial"});
  both("Msh", "N m", "the inertial shaking moment |Msh|", {"Msh_inertial"});
  for (const Input& in : l.inputs) {
    const bool one = l.inputs.size() == 1;
    const std::string column = one ? "tau" : "tau_" + in.name;
    const bool angle = in.kind == Input::Kind::kAngle;
    both(column, angle ? "N m" : "N",
         std::string(angle ? "the drive torque" : "the drive force") +
             (one ? "" : " of " + in.name) + " |" + column + "|",
         {column});
  }
  const detail::System& system = model.system();
  for (std::size_t i = 0; i < model.ground_nodes().size(); ++i) {
    // a ground node no link holds (a spring's anchor) has no bearing: its pull is the spring's
    if (system.ground_first[i + 1] == system.ground_first[i]) continue;
    const std::string& node = l.nodes[static_cast<std::size_t>(model.ground_nodes()[i])].name;
    const std::string name = "R" + node;
    both(name, "N", "the bearing force |" + name + "| at ground node " + node,
         {name + "x", name + "y"});
  }
  for (int k : model.frame_springs()) {
    const Spring& sp = l.springs[static_cast<std::size_t>(k)];
    const int anchor = l.nodes[static_cast<std::size_t>(sp.a)].ground ? sp.a : sp.b;
    const std::string& node = l.nodes[static_cast<std::size_t>(anchor)].name;
    const std::string name = "R" + node + "_" + sp.name;
    both(name, "N", "the pull |" + name + "| of spring " + sp.name + " on the frame at " + node,
         {name + "x", name + "y"});
  }
  for (int s : model.frame_guides()) {
    const std::string name = "R" + l.sliders[static_cast<std::size_t>(s)].name;
    both(name, "N",
         "the guide force |" + name + "| of slider " + l.sliders[static_cast<std::size_t>(s)].name,
         {name + "x", name + "y"});
  }
  for (const BalanceShaft& b : l.shafts) {
    const std::string name = "R" + b.name;
    both(name, "N", "the bearing force |" + name + "| of balance shaft " + b.name,
         {name + "x", name + "y"});
  }
  for (const JointForce& j : model.joints()) {
    const std::string name = "F" + j.name;
    t.push_back({name + "_max",
                 "N",
                 "peak of the joint force |" + name + "|",
                 Statistic::kMax,
                 {name + "x", name + "y"}});
  }
  for (int k : model.link_guides()) {
    const std::string& slider = l.sliders[static_cast<std::size_t>(k)].name;
    const std::string name = "F" + slider + "_guide";
    t.push_back({name + "_max",
                 "N",
                 "peak of the force |" + name + "| between slider " + slider + " and its guide",
                 Statistic::kMax,
                 {name + "x", name + "y"}});
  }
  for (const TotalMetricInfo& m : kTotalMetrics) {
    t.push_back({m.name, m.unit, m.words, m.statistic,
                 m.force ? std::vector<std::string>{"Fshx", "Fshy"}
                         : std::vector<std::string>{"Msh"}});
  }
  return t;
}

namespace {

// the columns of each metric in `table`
std::vector<std::vector<int>> metric_columns(const std::vector<ColumnMetric>& metrics,
                                             const Series& table) {
  std::vector<std::vector<int>> out;
  for (const ColumnMetric& m : metrics) {
    std::vector<int> c;
    for (const std::string& name : m.columns) c.push_back(table.column(name));
    out.push_back(c);
  }
  return out;
}

// the magnitude a metric summarises, in one row
double magnitude(const std::vector<int>& c, std::span<const double> row) {
  if (c.size() == 1) return std::abs(row[static_cast<std::size_t>(c[0])]);
  return core::magnitude(row[static_cast<std::size_t>(c[0])], row[static_cast<std::size_t>(c[1])]);
}

}  // namespace

std::vector<double> metric_values(const std::vector<ColumnMetric>& metrics, const Series& table) {
  std::vector<double> out(metrics.size(), 0.0);
  const std::size_t rows = table.rows();
  if (rows == 0) return out;
  const std::vector<std::vector<int>> columns = metric_columns(metrics, table);
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    const ColumnMetric& m = metrics[k];
    RmsAccumulator rms;
    double peak = 0;
    for (std::size_t i = 0; i < rows; ++i) {
      const double x = magnitude(columns[k], table.row(i));
      if (m.statistic == Statistic::kRms) {
        rms.add(x);
      } else {
        peak = std::max(peak, x);
      }
    }
    out[k] = m.statistic == Statistic::kRms ? rms.rms() : peak;
  }
  return out;
}

Eigen::MatrixXd metric_gradients(const std::vector<ColumnMetric>& metrics,
                                 const FreeSensitivities& run) {
  const Series& table = run.trajectory.table;
  const auto m = static_cast<Eigen::Index>(run.parameters.size());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(metrics.size()), m);
  const std::size_t rows = table.rows();
  if (rows == 0 || run.derivative.size() != run.parameters.size()) return g;
  const std::vector<double> values = metric_values(metrics, table);
  const std::vector<std::vector<int>> columns = metric_columns(metrics, table);
  // a metric's vector in a row of a table: one column as (x, 0), or an x, y pair
  const auto vector_in = [](const std::vector<int>& c, std::span<const double> row) {
    return Vec2(row[static_cast<std::size_t>(c[0])],
                c.size() > 1 ? row[static_cast<std::size_t>(c[1])] : 0.0);
  };
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    const auto v = [&](std::size_t i) { return vector_in(columns[k], table.row(i)); };
    const std::size_t at = core::detail::peak_sample(rows, v);
    for (Eigen::Index j = 0; j < m; ++j) {
      const Series& d = run.derivative[static_cast<std::size_t>(j)];
      g(static_cast<Eigen::Index>(k), j) = core::detail::metric_derivative(
          metrics[k].statistic, rows, values[k], at, v,
          [&](std::size_t i) { return vector_in(columns[k], d.row(i)); });
    }
  }
  return g;
}

Eigen::MatrixXd metric_gradients(const Model& model, const SimulateOptions& options,
                                 const std::vector<ColumnMetric>& metrics,
                                 const FreeSensitivities& run, const std::vector<Peak>& peaks) {
  Eigen::MatrixXd g = metric_gradients(metrics, run);
  const Series& table = run.trajectory.table;
  if (table.rows() == 0 || run.derivative.size() != run.parameters.size() ||
      peaks.size() != metrics.size()) {
    return g;
  }
  const std::vector<std::vector<int>> columns = metric_columns(metrics, table);
  const auto vector_in = [](const std::vector<int>& c, const std::vector<double>& row) {
    return Vec2(row[static_cast<std::size_t>(c[0])],
                c.size() > 1 ? row[static_cast<std::size_t>(c[1])] : 0.0);
  };
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    if (metrics[k].statistic != Statistic::kMax || !(peaks[k].value > 0)) continue;
    const std::optional<InstantDerivatives> d =
        free_derivatives_at(model, options, run, peaks[k].t);
    if (!d) continue;  // the largest sample's, as metric_gradients(metrics, run) has it
    const Vec2 v = vector_in(columns[k], d->row);
    const double size = core::magnitude(v.x(), v.y());
    if (!(size > 0)) continue;
    for (std::size_t j = 0; j < d->derivative.size(); ++j) {
      g(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) =
          v.dot(vector_in(columns[k], d->derivative[j])) / size;
    }
  }
  return g;
}

namespace {

// The positions of row i of a run's table, every node (ground nodes where they are drawn).
class RowPositions {
 public:
  RowPositions(const Model& model, const Series& table) : nodes_(model.linkage().nodes) {
    xy_.assign(nodes_.size(), {-1, -1});
    for (std::size_t n = 0; n < nodes_.size(); ++n) {
      if (!nodes_[n].ground)
        xy_[n] = {table.column("x_" + nodes_[n].name), table.column("y_" + nodes_[n].name)};
    }
  }
  Vec2 at(const Series& table, std::size_t i, std::size_t n) const {
    return nodes_[n].ground ? nodes_[n].position
                            : Vec2(table.at(i, static_cast<std::size_t>(xy_[n].first)),
                                   table.at(i, static_cast<std::size_t>(xy_[n].second)));
  }
  std::vector<Vec2> row(const Series& table, std::size_t i) const {
    std::vector<Vec2> x(nodes_.size());
    for (std::size_t n = 0; n < nodes_.size(); ++n) x[n] = at(table, i, n);
    return x;
  }

 private:
  const std::vector<Node>& nodes_;
  std::vector<std::pair<int, int>> xy_;
};

// The metrics over the run's table (sample times t), every peak resolved between the samples by
// `row_at(s)`: the whole row at time s, or null where it cannot be evaluated; `extra`: instants
// between the samples, and after the last up to where a stopped run stopped (increasing), whose
// rows the peaks' searches start from with the samples' (a free run's step_instants()).
template <class RowAt>
std::vector<double> resolved_values(const std::vector<ColumnMetric>& metrics, const Series& table,
                                    const std::vector<double>& t, double period,
                                    const RowAt& row_at, std::vector<Peak>* peaks,
                                    std::span<const double> extra = {}) {
  std::vector<double> out = metric_values(metrics, table);
  if (peaks) peaks->assign(metrics.size(), Peak{});
  const std::size_t rows = table.rows();
  if (rows == 0) return out;
  const std::vector<std::vector<int>> columns = metric_columns(metrics, table);
  // the rows searched: the samples', with the extra instants' rows between them, each evaluated
  // once for every peak
  std::vector<double> dense_t;
  Series dense;
  dense.columns = table.columns;
  if (!extra.empty()) {
    std::size_t e = 0;
    for (std::size_t i = 0; i < rows; ++i) {
      dense_t.push_back(t[i]);
      const std::span<const double> r = table.row(i);
      dense.values.insert(dense.values.end(), r.begin(), r.end());
      for (; e < extra.size() && (i + 1 == rows || extra[e] < t[i + 1]); ++e) {
        if (const double* row = row_at(extra[e])) {
          dense_t.push_back(extra[e]);
          dense.values.insert(dense.values.end(), row, row + table.width());
        }
      }
    }
  }
  const bool densified = dense_t.size() > rows;
  const Series& searched = densified ? dense : table;
  const std::vector<double>& searched_t = densified ? dense_t : t;
  std::vector<double> x(searched.rows());
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    if (metrics[k].statistic != Statistic::kMax) {
      if (peaks) (*peaks)[k] = {out[k], 0.0};
      continue;
    }
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = magnitude(columns[k], searched.row(i));
    const Peak p = resolved_peak(searched_t, x, period, [&](double s) {
      const double* row = row_at(s);
      return row ? magnitude(columns[k], {row, table.width()}) : std::nan("");
    });
    out[k] = p.value;
    if (peaks) (*peaks)[k] = p;
  }
  return out;
}

}  // namespace

double driven_period(const Model& model, const DrivenScene& scene, const Trajectory& run) {
  // periodic: whole revolutions of the one input that moves, run to the end
  const Linkage& l = model.linkage();
  int moving = 0;
  double period = 0;
  for (std::size_t k = 0; k < l.inputs.size() && k < scene.speeds.size(); ++k) {
    if (scene.speeds[k] == 0) continue;
    ++moving;
    if (l.inputs[k].kind == Input::Kind::kAngle)
      period = 2 * std::numbers::pi / std::abs(scene.speeds[k]) * scene.revolutions;
  }
  return moving != 1 || scene.duration > 0 || !run.ok() ? 0.0 : period;
}

struct DrivenRows::State {
  State(const Model& m, const DrivenScene& sc, const Trajectory& r)
      : model(m), scene(sc), table(r.table), positions(m, r.table), ws(m) {
    t = table.column_values("t");
    start = scene.start.empty() ? drawn_inputs(model) : scene.start;
    period = driven_period(model, scene, r);
    row.columns = table.columns;
    z.resize(start.size());
    zero.assign(start.size(), 0.0);
    h = table.rows() > 1 ? t[1] - t[0] : 0.0;
  }
  const Model& model;
  const DrivenScene& scene;
  const Series& table;
  RowPositions positions;
  Workspace ws;
  Series row;
  std::vector<double> t, start, z, zero;
  double period = 0, h = 0;
  double cached_t = std::nan("");
};

DrivenRows::DrivenRows(const Model& model, const DrivenScene& scene, const Trajectory& run)
    : state_(std::make_unique<State>(model, scene, run)) {}
DrivenRows::~DrivenRows() = default;
double DrivenRows::period() const { return state_->period; }

const double* DrivenRows::at(double s) {
  State& st = *state_;
  const std::size_t rows = st.table.rows();
  if (rows == 0) return nullptr;
  if (s != st.cached_t) {
    st.cached_t = s;
    st.row.values.clear();
    const std::vector<double>& t = st.t;
    const double u = st.period > 0 ? std::fmod(s - t[0] + st.period, st.period) + t[0] : s;
    const auto i = static_cast<std::size_t>(std::clamp(
        std::round((u - t[0]) / (st.h > 0 ? st.h : 1.0)), 0.0, static_cast<double>(rows - 1)));
    const std::vector<Vec2> guess = st.positions.row(st.table, i);
    for (std::size_t k = 0; k < st.z.size(); ++k) st.z[k] = st.start[k] + st.scene.speeds[k] * s;
    if (!solve_position(st.model, st.ws, guess, st.z)) return nullptr;
    // Newton's method from the nearest sample may land on another branch where the samples are
    // far apart; the blocks' closed forms keep the sample's branch however far (1 or 2 samples
    // per turn)
    for (std::size_t n = 0; n < guess.size() && !st.ws.by_blocks; ++n) {
      if ((st.ws.instant.x[n] - guess[n]).norm() > 0.25 * st.model.length_scale()) return nullptr;
    }
    if (!inverse_dynamics(st.model, st.ws, s, st.scene.speeds, st.zero)) return nullptr;
    append_row(st.model, st.ws.instant, st.row);
  }
  return st.row.values.empty() ? nullptr : st.row.values.data();
}

std::vector<double> metric_values(const Model& model, const DrivenScene& scene,
                                  const std::vector<ColumnMetric>& metrics, const Trajectory& run,
                                  std::vector<Peak>* peaks) {
  DrivenRows rows(model, scene, run);
  const std::vector<double> t = run.table.column_values("t");
  return resolved_values(
      metrics, run.table, t, rows.period(), [&rows](double s) { return rows.at(s); }, peaks);
}

std::vector<double> metric_values(const Model& model, const SimulateOptions& options,
                                  const std::vector<ColumnMetric>& metrics, const Trajectory& run,
                                  std::vector<Peak>* peaks) {
  const Series& table = run.table;
  const std::vector<double> t = table.column_values("t");
  const RowPositions positions(model, table);
  const double reach = 0.25 * model.length_scale();
  // a known instant: the run's state there and its row
  struct Known {
    FreeState state;
    std::vector<double> row;
  };
  core::detail::KnownInstants<Known> known(t, run.stop_time);
  const auto sample = [&](std::size_t i) {
    const std::span<const double> r = table.row(i);
    return Known{free_state(model, run, i), std::vector<double>(r.begin(), r.end())};
  };
  if (std::optional<FreeState> stop = free_stop_state(model, run)) {
    known.add(run.stop_time, Known{std::move(*stop), run.stop_row});
  }
  Series row;
  row.columns = table.columns;
  // the run continued from `from` at t0 to s; none where it cannot be, or where it lands on
  // another assembly than the run's: a node further from where the samples around s have it
  // than a quarter of the linkage's size beyond the samples' own step
  const auto integrate = [&](double t0, const Known& from, double s) -> std::optional<Known> {
    if (s == t0) return from;
    row.values.clear();
    std::optional<FreeState> state = free_state_from(model, options, from.state, s, row);
    if (!state) return std::nullopt;
    const auto i =
        static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), s) - t.begin()) - 1;
    const std::size_t j = std::min(i + 1, t.size() - 1);
    for (std::size_t n = 0; n < state->x.size(); ++n) {
      const Vec2 a = positions.at(table, i, n), b = positions.at(table, j, n);
      const double off = std::min((state->x[n] - a).norm(), (state->x[n] - b).norm());
      if (off > reach + (b - a).norm()) return std::nullopt;
    }
    return Known{std::move(*state), row.values};
  };
  // the instant row_at() gave last, for the next quantity's search
  double last_t = std::nan("");
  std::optional<Known> last;
  const auto row_at = [&](double s) -> const double* {
    if (s != last_t) {
      last_t = s;
      last = known.at(s, sample, integrate);
    }
    return last ? last->row.data() : nullptr;
  };
  std::vector<double> values =
      resolved_values(metrics, table, t, 0.0, row_at, peaks,
                      step_instants(t, run.steps_to, run.stop_time, run.steps));
  // where each peak lies: the inputs' values there
  if (peaks && table.rows() > 0) {
    std::vector<int> inputs;
    const Linkage& l = model.linkage();
    for (const Input& in : l.inputs) {
      inputs.push_back(
          in.kind == Input::Kind::kAngle
              ? table.column("theta_" + l.links[static_cast<std::size_t>(in.link)].name)
              : table.column("s_" + l.sliders[static_cast<std::size_t>(in.slider)].name));
    }
    for (std::size_t k = 0; k < metrics.size(); ++k) {
      if (metrics[k].statistic != Statistic::kMax) continue;
      const double* r = row_at((*peaks)[k].t);
      if (!r) continue;
      for (const int c : inputs) (*peaks)[k].inputs.push_back(r[c]);
    }
  }
  return values;
}

}  // namespace bd::core::planar
