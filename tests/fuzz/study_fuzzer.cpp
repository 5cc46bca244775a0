// libFuzzer target: any bytes as a study file, through the loader and every validation a
// `balance-design validate` runs (YAML, keys, types, ranges, assembly, balance synthesis,
// optimisation and sweep requests). A bad input must end as one StudyError: one line, located,
// no control characters. Anything else (a crash, a sanitizer report, another exception, a hang
// or unbounded memory, which libFuzzer's -timeout and -rss_limit_mb catch) is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "studies/study/load_study.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)bd::studies::parse_study(text, "fuzz.yaml");
  } catch (const bd::studies::StudyError& e) {
    const std::string what = e.what();
    // one line, FILE:LINE:COLUMN: message
    for (const char c : what) {
      if (static_cast<unsigned char>(c) < 0x20) std::abort();
    }
    if (what.rfind("fuzz.yaml:", 0) != 0 || e.line() < 1 || e.column() < 1) std::abort();
  }
  // any other exception escapes: libFuzzer reports it as a crash
  return 0;
}
