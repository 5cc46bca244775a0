// The study page: which page a study gets (by its linkage type), where gnuplot is, and writing
// report.html.
#include "studies/report/report.hpp"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "studies/report/pages.hpp"
#include "studies/report/report_support.hpp"
#include "studies/run/files.hpp"

namespace bd::studies {

namespace fs = std::filesystem;
using namespace report_support;  // NOLINT(google-build-using-namespace): the page builders

std::string find_gnuplot() {
  const char* env = std::getenv("BD_GNUPLOT");
  const std::string name = env && *env ? env : "gnuplot";
  if (name.find('/') != std::string::npos) return executable(name) ? name : std::string();
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    const fs::path p = fs::path(d.empty() ? "." : d) / name;
    if (executable(p)) return p.string();
  }
  return {};
}

std::string linkage_tables_html(const Study& study) {
  return study.is_fourbar() ? fourbar_linkage_tables(study.fourbar())
                            : planar_linkage_tables(study.planar());
}

std::string report_html(const Study& study, const fs::path& dir, const std::string& gnuplot) {
  const fs::path summary_file = dir / "summary.json";
  if (!fs::exists(summary_file)) {
    throw std::runtime_error(summary_file.string() + " not found: not the output folder of a run");
  }
  const Json summary = parse_json(read_file(summary_file), summary_file.string());
  return study.is_fourbar() ? fourbar_report_html(study, dir, gnuplot, summary)
                            : planar_report_html(study, dir, gnuplot, summary);
}

fs::path write_report(const Study& study, const fs::path& dir) {
  const std::string html = report_html(study, dir, find_gnuplot());
  const fs::path target = dir / "report.html";
  write_text_file(html, target);  // whole or not at all
  return target;
}

}  // namespace bd::studies
