#include "studies/study/load_study.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "core/number_text.hpp"
#include "core/printable.hpp"
#include "studies/study/load_study_internal.hpp"
#include "studies/study/sections.hpp"

namespace bd::studies {

// control characters (a key holding a newline or a NUL) are escaped: what() is one line
StudyError::StudyError(std::string file, int line, int column, std::string message)
    : InputError(line > 0 ? text::printable(file) + ":" + std::to_string(line) + ":" +
                                std::to_string(column) + ": " + text::printable(message)
                          : text::printable(file) + ": " + text::printable(message)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      message_(text::printable(message)) {}

namespace {

using namespace detail;

// the longest study name, and what the balanced or optimised design's study appends to it
constexpr std::size_t kMaxName = 100;
constexpr std::string_view kBalancedSuffix = "-balanced";
constexpr std::string_view kOptimizedSuffix = "-optimized";
// the tightest relative tolerance a study may ask of the integrator
constexpr double kMinTolerance = 1e-14;

class StudyParser {
 public:
  explicit StudyParser(const Reporter& r) : r_(r) {}

  Study parse(const YAML::Node& root) {
    Study study;
    study.source = r_.source();
    if (!root.IsDefined() || root.IsNull()) {
      r_.fail(YAML::Mark(),
              "the study file is empty; expected the keys name, linkage and scene "
              "(and optionally loads, method, tolerance)");
    }
    const MapReader top(r_, root, "", mark_of(root, YAML::Mark()),
                        "of keys (name, linkage, scene, ...)");
    top.check_keys({"name", "linkage", "loads", "scene", "method", "tolerance", "balance",
                    "optimize", "sweep"});
    const MapReader::Entry& name = top.require("name", "the study's name, used in output names");
    study.name = read_name(name);
    read_linkage_and_scene(top, study);
    if (const MapReader::Entry* method = top.find("method"))
      study.method = read_method(*method, study);
    if (const MapReader::Entry* tol = top.find("tolerance")) study.tolerance = read_tolerance(*tol);
    read_design_sections(top, name, study);
    // last: the study above is the sweep's base, valid on its own; the paths are checked
    // against the file's tree
    if (const MapReader::Entry* sweep = top.find("sweep"))
      study.sweep = read_sweep(r_, *sweep, root);
    return study;
  }

 private:
  // linkage.type decides which reader reads the linkage, the loads and the scene
  void read_linkage_and_scene(const MapReader& top, Study& study) {
    const MapReader::Entry& linkage = top.require("linkage", "the mechanism");
    const MapReader lk(r_, linkage.value, "linkage", linkage.key_mark,
                       "(type: fourbar or planar, and the linkage's data)");
    const MapReader::Entry& type = lk.require("type", "the kind of linkage: fourbar or planar");
    const std::string t = read_text(r_, type, "linkage.type");
    const MapReader::Entry& scene = top.require("scene", "what to simulate: free or driven");
    if (t == "fourbar") {
      FourBarSection section(r_);
      const core::FourBar model = section.read(linkage, top.find("loads"));
      study.linkage = model;
      study.parts = section.parts();
      study.scene = section.read_scene(scene, model);
    } else if (t == "planar") {
      PlanarSection section(r_);
      const core::planar::Linkage model = section.read(linkage, top.find("loads"));
      study.linkage = model;
      study.parts = section.parts();
      study.scene = section.read_scene(scene, model);
    } else {
      r_.fail(mark_of(type.value, type.key_mark),
              "linkage.type '" + t + "' is not supported; expected fourbar or planar");
    }
  }

  // balance or optimize: the design sections, each read by its linkage type's reader
  void read_design_sections(const MapReader& top, const MapReader::Entry& name, Study& study) {
    const MapReader::Entry* balance = top.find("balance");
    const MapReader::Entry* opt = top.find("optimize");
    if (balance && opt) {
      // one or the other: a balanced design and an optimised one would compete for the outputs
      const bool later = opt->key_mark.pos > balance->key_mark.pos;
      const MapReader::Entry& second = later ? *opt : *balance;
      const MapReader::Entry& first = later ? *balance : *opt;
      r_.fail(second.key_mark, "a study has a balance section or an optimize section, not both (" +
                                   first.key + " is given at line " +
                                   std::to_string(first.key_mark.line + 1) +
                                   "); to optimise a balanced design, ask for force_balance "
                                   "in optimize.constraints");
    }
    if (balance) {
      check_name_room(name, study, kBalancedSuffix, "a balance section", "balanced.yaml");
      if (study.is_fourbar()) {
        study.balance = read_balance(r_, *balance, study.fourbar());
      } else {
        study.planar_balance = read_planar_balance(r_, *balance, study.planar());
      }
    }
    if (opt) {
      check_name_room(name, study, kOptimizedSuffix, "an optimize section", "optimized.yaml");
      if (study.is_fourbar()) {
        study.optimize = read_optimize(r_, *opt, study);
      } else {
        study.planar_optimize = read_planar_optimize(r_, *opt, study);
      }
    }
  }

  // the second design is written as a study named <name><suffix>
  void check_name_room(const MapReader::Entry& name, const Study& study, std::string_view suffix,
                       const char* section, const char* file) {
    if (study.name.size() <= kMaxName - suffix.size()) return;
    r_.fail(mark_of(name.value, name.key_mark),
            "name must have at most " + std::to_string(kMaxName - suffix.size()) +
                " characters in a study with " + section + " (" + file + " is named <name>" +
                std::string(suffix) + "), got " + std::to_string(study.name.size()));
  }

  std::string read_name(const MapReader::Entry& e) {
    const std::string name = read_text(r_, e, "name");
    const YAML::Mark m = mark_of(e.value, e.key_mark);
    if (name.empty() || name.size() > kMaxName) {
      r_.fail(m, "name must have 1 to " + std::to_string(kMaxName) + " characters, got " +
                     std::to_string(name.size()));
    }
    for (char c : name) {
      const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
      if (!ok) {
        r_.fail(m,
                "name may use only letters, digits, '.', '_' and '-' (it names the output "
                "directory), got " +
                    describe(e.value));
      }
    }
    if (name[0] == '.') r_.fail(m, "name must not start with '.', got " + describe(e.value));
    return name;
  }

  Method read_method(const MapReader::Entry& e, const Study& study) {
    const std::string name = read_text(r_, e, "method");
    const YAML::Mark m = mark_of(e.value, e.key_mark);
    const auto method = method_named(name);
    if (!method) {
      std::vector<std::string> all;
      for (Method x : kMethods) all.emplace_back(to_string(x));
      r_.fail(m, "unknown method '" + name + "'; expected one of " + join(all));
    }
    if (!study.is_fourbar() && formulation_of(*method)) {
      r_.fail(m, "method " + name +
                     " is one of the four-bar's formulations; a planar linkage is computed by "
                     "auto, truss or truss-dae");
    }
    return *method;
  }

  double read_tolerance(const MapReader::Entry& e) {
    const double tol = read_number(r_, e, "tolerance", "");
    const YAML::Mark m = mark_of(e.value, e.key_mark);
    if (!(tol > 0 && tol < 1)) {
      r_.fail(m,
              "tolerance must be > 0 and < 1 (a relative tolerance), got " + text::shortest(tol));
    }
    if (tol < kMinTolerance) {
      // double precision carries about 16 digits: the integrator cannot meet a tighter one
      r_.fail(m, "tolerance must be >= 1e-14 (a relative tolerance; double precision carries "
                 "about 16 digits), got " + text::shortest(tol));
    }
    core::SimulateOptions options;
    options.tolerance = tol;
    if (const auto problem = options.validate()) r_.fail(m, "tolerance: " + problem->text());
    return tol;
  }

  const Reporter& r_;
};

}  // namespace

namespace internal {

Study parse_study_tree(const YAML::Node& root, const std::string& source_name) {
  const Reporter r(source_name);
  StudyParser parser(r);
  try {
    Study study = parser.parse(root);
    study.units_read = r.units_read();
    return study;
  } catch (const YAML::Exception& e) {
    // conversions are checked before use, so this is unexpected; still report it in place
    r.fail(e.mark, e.msg);
  }
}

std::optional<std::vector<PathStep>> parse_path(const std::string& path) {
  auto name_char = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  };
  std::vector<PathStep> steps;
  std::size_t i = 0;
  const std::size_t n = path.size();
  while (true) {
    // a key, then any number of [index]
    const std::size_t start = i;
    while (i < n && name_char(path[i])) ++i;
    if (i == start) return std::nullopt;
    steps.push_back({path.substr(start, i - start), 0});
    while (i < n && path[i] == '[') {
      const std::size_t digits = ++i;
      while (i < n && path[i] >= '0' && path[i] <= '9') ++i;
      const std::size_t len = i - digits;
      // one canonical spelling per element (no leading zeros), and small enough to convert
      if (len == 0 || len > 9 || (len > 1 && path[digits] == '0')) return std::nullopt;
      if (i == n || path[i] != ']') return std::nullopt;
      steps.push_back({"", std::stoul(path.substr(digits, len))});
      ++i;
    }
    if (i == n) return steps;
    if (path[i] != '.') return std::nullopt;
    ++i;
  }
}

YAML::Node node_at(YAML::Node root, const std::vector<PathStep>& steps) {
  // Node::reset() rebinds; assigning a Node would overwrite the node it refers to
  YAML::Node node;
  node.reset(root);
  for (const PathStep& s : steps) {
    const YAML::Node next = s.key.empty() ? node[s.index] : node[s.key];
    node.reset(next);
  }
  return node;
}

}  // namespace internal

namespace {

// Counts the documents of a YAML text without building them (yaml-cpp's event interface).
class DocumentMarks : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> starts;
  std::vector<YAML::Mark> scalars;  // where each scalar starts (a quoted one at its quote)
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    scalars.push_back(mark);
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

// A YAML error at its place; yaml-cpp's words for a tab in the indentation ("illegal map value"
// and the like) are replaced by what it is, at the first tab in a line's indentation up to the
// error.
[[noreturn]] void fail_yaml(const std::string& text, const YAML::Exception& e, const Reporter& r) {
  std::istringstream lines(text);
  std::string line;
  for (int row = 0; std::getline(lines, line) && (e.mark.line < 0 || row <= e.mark.line); ++row) {
    const std::size_t indent = line.find_first_not_of(" \t");
    const std::size_t tab = line.find('\t');
    if (tab != std::string::npos && tab < indent) {
      YAML::Mark at;
      at.line = row;
      at.column = static_cast<int>(tab);
      r.fail(at, "tabs are not allowed in YAML indentation; indent with spaces");
    }
  }
  // yaml-cpp's words for the mistakes people make, said as what to look at (its words kept at
  // the end, for a search)
  struct Meaning {
    const char* yaml;
    const char* what;
  };
  static constexpr Meaning kMeanings[] = {
      {YAML::ErrorMsg::MAP_VALUE,
       "a 'key: value' where none can be: the keys of one map line up, so check this line's "
       "indentation against the keys above it; a value holding ': ' needs quotes"},
      {YAML::ErrorMsg::BLOCK_ENTRY,
       "a '- ' list item where none can be: the items of one list line up, so check this line's "
       "indentation against the items or the key above it"},
      {YAML::ErrorMsg::END_OF_MAP,
       "a map's keys do not line up: check the indentation of this line and the keys above it"},
      {YAML::ErrorMsg::END_OF_SEQ,
       "a list's items do not line up: check the indentation of this line and the items above it"},
      {YAML::ErrorMsg::END_OF_MAP_FLOW, "a '{' is not closed by a '}'"},
      {YAML::ErrorMsg::END_OF_SEQ_FLOW, "a '[' is not closed by a ']'"},
      {YAML::ErrorMsg::FLOW_END, "a '}' or ']' closes nothing that was opened"},
      {YAML::ErrorMsg::EOF_IN_SCALAR, "a quoted value is not closed by its quote"},
  };
  for (const Meaning& m : kMeanings) {
    if (e.msg == m.yaml) r.fail(e.mark, std::string(m.what) + " (YAML: " + e.msg + ")");
  }
  r.fail(e.mark, e.msg);
}

// A quote left open: YAML lets a quoted value run on over lines, so a value whose closing quote
// is forgotten takes the lines below as its text up to the next quote, and the keys there go
// missing without a YAML error. A quoted value that runs on to a line starting with a 'key:' or
// a '- ' item no deeper than the line it opened on (which YAML allows as no continuation of a
// value in a block, though yaml-cpp takes it) is refused at its opening quote.
void check_quotes_closed(const std::string& text, const std::vector<YAML::Mark>& scalars,
                         const Reporter& r) {
  const auto indent_of = [&](std::size_t line_start) {
    const std::size_t end = text.find_first_not_of(' ', line_start);
    return (end == std::string::npos ? text.size() : end) - line_start;
  };
  for (const YAML::Mark& at : scalars) {
    if (at.pos < 0 || static_cast<std::size_t>(at.pos) >= text.size()) continue;
    const auto open = static_cast<std::size_t>(at.pos);
    const char quote = text[open];
    if (quote != '"' && quote != '\'') continue;
    std::size_t close = open + 1;  // the closing quote ('' and \" are quotes within)
    for (; close < text.size(); ++close) {
      if (quote == '"' && text[close] == '\\') {
        ++close;
      } else if (text[close] == quote) {
        if (quote == '\'' && close + 1 < text.size() && text[close + 1] == '\'') {
          ++close;
        } else {
          break;
        }
      }
    }
    if (close >= text.size()) {  // no closing quote at all: yaml-cpp takes the file's end
      r.fail(at, "this quoted value is not closed: no closing quote before the end of the file");
    }
    const std::size_t first_line = text.rfind('\n', open) + 1;  // npos + 1 == 0
    const std::size_t depth = indent_of(first_line);
    int row = at.line;
    for (std::size_t nl = text.find('\n', open); nl < close; nl = text.find('\n', nl + 1)) {
      ++row;
      const std::size_t start = nl + 1;
      const std::size_t indent = indent_of(start);
      if (indent > depth || start + indent >= close) continue;
      const std::size_t eol = std::min(text.find('\n', start), text.size());
      const std::string_view line(text.data() + start + indent, eol - start - indent);
      const bool item = line.rfind("- ", 0) == 0 || line == "-";
      const std::size_t colon = line.find(':');
      const bool key = colon != std::string_view::npos && colon > 0 &&
                       (colon + 1 == line.size() || line[colon + 1] == ' ') &&
                       line.substr(0, colon).find_first_of("\"' ") == std::string_view::npos;
      if (!item && !key) continue;
      r.fail(at, "this quoted value is not closed on its line: it runs on to line " +
                     std::to_string(row + 1) + " ('" + std::string(line.substr(0, 40)) +
                     "') and takes it as text; close the quote");
    }
  }
}

// The text's one YAML document. Not YAML::LoadAll: yaml-cpp 0.7 never consumes a token that can
// start no node (a ',' outside brackets, as in a file holding only ","), so LoadAll returns an
// endless list of empty documents at that token and fills the memory. Here the parser is asked
// for at most two documents: a second one that starts with '---' (or a '%' directive) is a
// second document; one that starts anywhere else starts at text the first document could not
// take, which is reported there.
YAML::Node one_document(const std::string& text, const Reporter& r) {
  DocumentMarks marks;
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    for (int i = 0; i < 2 && parser.HandleNextDocument(marks); ++i) {
    }
  } catch (const YAML::Exception& e) {
    check_quotes_closed(text, marks.scalars, r);  // the cause, where a quote ran on
    fail_yaml(text, e, r);
  }
  check_quotes_closed(text, marks.scalars, r);
  if (marks.starts.size() > 1) {
    const YAML::Mark& at = marks.starts[1];
    // a mark past the text (never expected of UTF-8 text) is taken as its end
    const std::size_t pos =
        at.pos >= 0 ? std::min(static_cast<std::size_t>(at.pos), text.size()) : text.size();
    if (text.compare(pos, 3, "---") == 0 || text.compare(pos, 1, "%") == 0) {
      r.fail(at, "a study file holds one YAML document; found a second one (after '---')");
    }
    r.fail(at, "unexpected " + (pos < text.size() ? text::quoted_char(text[pos]) : "end") +
                   ": the study's YAML document cannot go on here (a study file is one map "
                   "of keys: name, linkage, scene, ...)");
  }
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail_yaml(text, e, r);
  }
}

// A study file is UTF-8 text. yaml-cpp reads a text that starts with a UTF-16 or UTF-32 byte
// order mark, or with a NUL byte in its first four, as UTF-16 or UTF-32, and its marks then count
// decoded characters, not the file's bytes and lines: a NUL byte (which UTF-8 text never holds
// and UTF-16 text always does) or such a mark is refused where it is.
void check_utf8_text(const std::string& text, const Reporter& r) {
  const auto starts = [&](std::string_view bom) { return text.compare(0, bom.size(), bom) == 0; };
  if (starts("\xFE\xFF") || starts("\xFF\xFE") || starts(std::string_view("\0\0\xFE\xFF", 4))) {
    r.fail(YAML::Mark(), "the study file is not UTF-8 text (it starts with a UTF-16 or UTF-32 "
                         "byte order mark); save it as UTF-8");
  }
  const std::size_t nul = text.find('\0');
  if (nul == std::string::npos) return;
  const std::size_t line_start = text.rfind('\n', nul);
  YAML::Mark at;
  at.line = static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(nul), '\n'));
  at.column = static_cast<int>(line_start == std::string::npos ? nul : nul - line_start - 1);
  r.fail(at, "the study file is not UTF-8 text: it holds a NUL byte here (a binary file, or "
             "text saved as UTF-16 or UTF-32?); save it as UTF-8");
}

}  // namespace

Study parse_study(const std::string& yaml_text, const std::string& source_name) {
  const Reporter r(source_name);
  check_utf8_text(yaml_text, r);
  const YAML::Node root = one_document(yaml_text, r);
  Study study = internal::parse_study_tree(root, source_name);
  // each point of a sweep is this text with its values set (point_study())
  if (study.sweep) study.sweep->study_text = yaml_text;
  return study;
}

Study load_study(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw StudyError(path, 0, 0, "is a directory, not a study file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw StudyError(path, 0, 0, "cannot open the study file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw StudyError(path, 0, 0, "cannot read the study file");
  return parse_study(text.str(), path);
}

}  // namespace bd::studies