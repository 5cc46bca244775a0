#include "studies/runner.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <variant>

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

// a file written under a temporary name in the target's directory and renamed into place by
// commit(); removed if never committed, so readers see the whole file or none
class AtomicFile {
 public:
  explicit AtomicFile(fs::path target) : target_(std::move(target)) {
    static std::atomic<unsigned> counter{0};
    // appended piece by piece: GCC 12 at -O3 warns falsely on `"." + std::string&&` (GCC bug
    // 105329, -Wrestrict)
    std::string name = ".";
    name.append(target_.filename().string()).append(".").append(std::to_string(::getpid()));
    name.append(".").append(std::to_string(counter++)).append(".tmp");
    temp_ = target_.parent_path() / name;
    file_ = std::fopen(temp_.c_str(), "wbx");
    if (!file_) fail("cannot create", temp_);
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() {
    if (file_) std::fclose(file_);
    if (!committed_) {
      std::error_code ec;
      fs::remove(temp_, ec);
    }
  }

  std::FILE* get() { return file_; }

  void commit() {
    const bool write_error = std::fflush(file_) != 0 || std::ferror(file_) != 0;
    const int saved = errno;
    const bool close_error = std::fclose(file_) != 0;
    file_ = nullptr;
    if (write_error || close_error) {
      errno = write_error ? saved : errno;
      fail("cannot write", temp_);
    }
    std::error_code ec;
    fs::rename(temp_, target_, ec);
    if (ec) {
      throw std::runtime_error("cannot rename " + temp_.string() + " to " + target_.string() +
                               ": " + ec.message());
    }
    committed_ = true;
  }

 private:
  [[noreturn]] static void fail(const char* what, const fs::path& p) {
    throw std::runtime_error(std::string(what) + " " + p.string() + ": " + std::strerror(errno));
  }

  fs::path target_, temp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

// "%.17g": round-trips every double
std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
// JSON has no inf or nan: those become null
std::string json_number(double v) { return std::isfinite(v) ? number(v) : "null"; }

void write_text(const std::string& text, const fs::path& file) {
  AtomicFile out(file);
  if (std::fwrite(text.data(), 1, text.size(), out.get()) != text.size()) {
    throw std::runtime_error("cannot write " + file.string() + ": " + std::strerror(errno));
  }
  out.commit();
}

}  // namespace

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20 || c == 0x7f) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += ch;  // UTF-8 bytes pass through unchanged
        }
    }
  }
  return out + "\"";
}

void write_timeseries(const core::Trajectory& trajectory, const fs::path& file) {
  AtomicFile out(file);
  std::FILE* f = out.get();
  std::fputs(kTimeseriesHeader, f);
  std::fputc('\n', f);
  for (std::size_t i = 0; i < trajectory.samples.size(); ++i) {
    const core::DynamicsSample& d = trajectory.samples[i];
    const core::FourBarState& s = d.state;
    const double t = i < trajectory.t.size() ? trajectory.t[i] : std::nan("");
    const double row[] = {t,         s.theta1,  s.theta2,  s.theta3,  s.omega1,  s.omega2,
                          s.omega3,  s.alpha1,  s.alpha2,  s.alpha3,  d.RA0.x(), d.RA0.y(),
                          d.RA3.x(), d.RA3.y(), d.Fsh.x(), d.Fsh.y(), d.Msh,     d.tau};
    for (std::size_t k = 0; k < std::size(row); ++k) {
      std::fprintf(f, k == 0 ? "%.17g" : ",%.17g", row[k]);
    }
    std::fputc('\n', f);
  }
  out.commit();
}

std::string summary_json(const Study& study, const RunResult& result) {
  const core::Trajectory& tr = result.trajectory;
  const core::Metrics& m = result.metrics;
  std::string j = "{\n";
  j += "  \"format\": \"balance-design summary v1\",\n";
  j += "  \"study\": " + json_string(study.name) + ",\n";
  j += "  \"source\": " + json_string(study.source) + ",\n";
  j += "  \"method\": {\"requested\": " + json_string(study.method_name()) +
       ", \"used\": " + json_string(core::to_string(result.method.formulation)) +
       ", \"reason\": " + json_string(result.method.reason) + "},\n";
  if (const auto* free = std::get_if<core::FreeScene>(&study.scene)) {
    j += "  \"scene\": {\"type\": \"free\", \"theta1\": " + json_number(free->theta1) +
         ", \"omega1\": " + json_number(free->omega1) +
         ", \"duration\": " + json_number(free->duration) +
         ", \"samples\": " + std::to_string(free->samples) + "},\n";
  } else {
    const auto& driven = std::get<core::DrivenScene>(study.scene);
    j += "  \"scene\": {\"type\": \"driven\", \"theta1\": " + json_number(driven.theta1) +
         ", \"omega1\": " + json_number(driven.omega1) +
         ", \"revolutions\": " + std::to_string(driven.revolutions) +
         ", \"samples\": " + std::to_string(driven.samples) + "},\n";
  }
  j += "  \"tolerance\": " + json_number(study.tolerance) + ",\n";
  j += "  \"samples\": " + std::to_string(tr.samples.size()) + ",\n";
  j += "  \"status\": " + json_string(core::to_string(tr.status)) + ",\n";
  j += std::string("  \"ok\": ") + (tr.ok() ? "true" : "false") + ",\n";
  j += "  \"message\": " + json_string(tr.message) + ",\n";
  j += "  \"steps\": " + std::to_string(tr.steps) + ",\n";
  j += "  \"rhs_evaluations\": " + std::to_string(tr.rhs_evaluations) + ",\n";
  j += "  \"metrics\": {\n";
  const std::pair<const char*, double> items[] = {{"Fsh_rms", m.Fsh_rms}, {"Fsh_max", m.Fsh_max},
                                                  {"Msh_rms", m.Msh_rms}, {"Msh_max", m.Msh_max},
                                                  {"tau_rms", m.tau_rms}, {"tau_max", m.tau_max},
                                                  {"RA0_max", m.RA0_max}, {"RA3_max", m.RA3_max}};
  for (std::size_t k = 0; k < std::size(items); ++k) {
    j += std::string("    \"") + items[k].first + "\": " + json_number(items[k].second) +
         (k + 1 < std::size(items) ? ",\n" : "\n");
  }
  j += "  }\n}\n";
  return j;
}

RunResult run_study(const Study& study, const fs::path& out_dir) {
  RunResult result;
  result.method = choose_method(study);

  // simulate first: an invalid scene throws before anything is created on disk
  core::SimulateOptions options;
  options.formulation = result.method.formulation;
  options.tolerance = study.tolerance;
  if (const auto* free = std::get_if<core::FreeScene>(&study.scene)) {
    result.trajectory = core::simulate_free(study.model, *free, options);
  } else {
    result.trajectory =
        core::simulate_driven(study.model, std::get<core::DrivenScene>(study.scene), options);
  }
  result.metrics = core::metrics(result.trajectory);

  // then the files, summary last: a summary.json means its timeseries.csv is complete
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create the output directory " + out_dir.string() + ": " +
                             ec.message());
  }
  result.timeseries = out_dir / "timeseries.csv";
  result.summary = out_dir / "summary.json";
  write_timeseries(result.trajectory, result.timeseries);
  write_text(summary_json(study, result), result.summary);
  return result;
}

}  // namespace bd::studies
