#include "studies/run/files.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "core/number_text.hpp"

namespace bd::studies {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const char* what, const fs::path& p) {
  throw std::runtime_error(std::string(what) + " " + p.string() + ": " + std::strerror(errno));
}

std::string quote(const std::string& text) {
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
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

AtomicFile::~AtomicFile() {
  if (file_) std::fclose(file_);
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
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
    throw std::runtime_error("cannot rename " + temp_.string() + " to " + target_.string() + ": " +
                             ec.message());
  }
  committed_ = true;
}

void remove_stale_temporaries(const fs::path& dir) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    // .<target>.<pid>.<counter>.tmp
    if (name.size() < 8 || name[0] != '.' || !name.ends_with(".tmp")) continue;
    const std::string stem = name.substr(0, name.size() - 4);
    const std::size_t counter = stem.rfind('.');
    if (counter == std::string::npos || counter == 0) continue;
    const std::size_t pid_at = stem.rfind('.', counter - 1);
    if (pid_at == std::string::npos || pid_at == 0) continue;
    const std::string pid_text = stem.substr(pid_at + 1, counter - pid_at - 1);
    const std::string counter_text = stem.substr(counter + 1);
    auto digits = [](const std::string& t) {
      return !t.empty() && t.size() < 10 &&
             std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    if (!digits(pid_text) || !digits(counter_text)) continue;
    const auto pid = static_cast<pid_t>(std::stol(pid_text));
    if (pid == ::getpid() || pid <= 0) continue;
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    std::error_code rm;
    fs::remove(it->path(), rm);
  }
}

void write_text_file(const std::string& text, const fs::path& file) {
  AtomicFile out(file);
  if (std::fwrite(text.data(), 1, text.size(), out.get()) != text.size()) {
    fail("cannot write", file);
  }
  out.commit();
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  return quote(text);
}

std::string csv_line_field(std::string text) {
  if (text.empty()) return text;
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return quote(text);
}

// NaN and infinities are no data: an empty field (issue 17)
std::string csv_number(double v) { return std::isfinite(v) ? text::exact(v) : std::string(); }

std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        out.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        out.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else if (c != '\r') {
      out.back() += c;
    }
  }
  return out;
}

}  // namespace bd::studies
