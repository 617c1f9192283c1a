// Runs the qdot binary as a user would (`qdot run MODEL.qd ... -o OUT.csv`), reads the CSV back and
// compares columns with closed forms at every output time. Header-only; used by the test_sim tests.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace qdot::simtest {

// The result of one `qdot run`: exit code, everything it wrote to standard error, the CSV columns.
struct RunResult {
  int exitCode = -1;
  std::string log;                       // standard error (errors, warnings, --stats)
  std::vector<std::string> header;       // CSV header, "time" first
  std::map<std::string, std::vector<double>> columns;
  std::size_t rows = 0;

  bool has(const std::string& name) const { return columns.count(name) != 0; }
  const std::vector<double>& col(const std::string& name) const {
    auto it = columns.find(name);
    if (it == columns.end()) {
      ADD_FAILURE() << "no column '" << name << "' in the CSV";
      static const std::vector<double> empty;
      return empty;
    }
    return it->second;
  }
  const std::vector<double>& time() const { return col("time"); }
};

inline std::string modelPath(const std::string& relative) { return std::string(QDOT_SOURCE_DIR) + "/" + relative; }

// A unique temporary file, removed when the object dies.
class TempFile {
 public:
  explicit TempFile(const char* suffix) {
    std::string pattern = (std::filesystem::temp_directory_path() / "qdot_sim_XXXXXX").string() + suffix;
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    int fd = mkstemps(buf.data(), static_cast<int>(std::strlen(suffix)));
    if (fd < 0) throw std::runtime_error(std::string("mkstemps: ") + std::strerror(errno));
    close(fd);
    path_ = buf.data();
  }
  ~TempFile() { std::remove(path_.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

inline std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// One CSV line split into fields (RFC 4180 quoting: "q[1,2]", "" inside quotes).
inline std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    char ch = line[i];
    if (quoted) {
      if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (ch == '"') {
        quoted = false;
      } else {
        field += ch;
      }
    } else if (ch == '"') {
      quoted = true;
    } else if (ch == ',') {
      fields.push_back(field);
      field.clear();
    } else if (ch != '\r') {
      field += ch;
    }
  }
  fields.push_back(field);
  return fields;
}

// `qdot run <source dir>/MODEL args... -o TMP.csv`, spawned directly (no shell), standard output to
// /dev/null, standard error captured.
inline RunResult runQdot(const std::string& model, const std::vector<std::string>& args) {
  TempFile csv(".csv"), err(".log");
  std::vector<std::string> argv = {QDOT_BINARY, "run", modelPath(model)};
  argv.insert(argv.end(), args.begin(), args.end());
  if (const char* extra = std::getenv("QDOT_TEST_RUN_ARGS")) {  // CTest runs the suite on each backend
    std::istringstream words(extra);
    for (std::string word; words >> word;) argv.push_back(word);
  }
  argv.push_back("-o");
  argv.push_back(csv.path());
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, err.path().c_str(), O_WRONLY | O_TRUNC, 0600);
  pid_t pid = 0;
  int rc = posix_spawn(&pid, QDOT_BINARY, &actions, nullptr, cargv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  RunResult r;
  if (rc != 0) {
    ADD_FAILURE() << "cannot start " << QDOT_BINARY << ": " << std::strerror(rc);
    return r;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.log = readAll(err.path());

  std::istringstream in(readAll(csv.path()));
  std::string line;
  if (std::getline(in, line)) r.header = splitCsvLine(line);
  std::vector<std::vector<double>> cols(r.header.size());
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    auto fields = splitCsvLine(line);
    if (fields.size() != r.header.size()) {
      ADD_FAILURE() << "CSV row with " << fields.size() << " fields, header has " << r.header.size() << ": " << line;
      continue;
    }
    for (std::size_t i = 0; i < fields.size(); ++i) {
      char* end = nullptr;
      double v = std::strtod(fields[i].c_str(), &end);
      if (end == fields[i].c_str() || *end != '\0') ADD_FAILURE() << "not a number in the CSV: '" << fields[i] << "'";
      cols[i].push_back(v);
    }
    ++r.rows;
  }
  for (std::size_t i = 0; i < r.header.size(); ++i) r.columns[r.header[i]] = std::move(cols[i]);
  return r;
}

inline std::string num(double v) {  // shortest text that reads back as v exactly
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The output grid as runtime/README.md defines it: start + k·interval while below stop, then stop.
inline void expectGrid(const RunResult& r, double start, double stop, double interval) {
  const auto& t = r.time();
  std::size_t n = 0;
  while (start + static_cast<double>(n) * interval < stop - 1e-9 * interval) ++n;
  ASSERT_EQ(t.size(), n + 1) << "rows: one per output time from " << start << " to " << stop << " every " << interval;
  for (std::size_t k = 0; k < n; ++k) EXPECT_NEAR(t[k], start + static_cast<double>(k) * interval, 1e-12 * (1 + std::fabs(stop)));
  EXPECT_EQ(t.back(), stop);
}

// What a comparison found: the largest error, the largest error/bound and where.
struct Deviation {
  double maxError = 0;
  double maxRatio = 0;  // max over rows of |error| / bound(t); must stay ≤ 1
  double timeOfMaxRatio = 0;
};

inline void report(const std::string& what, const Deviation& d) {
  std::cout << "[measured] " << ::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name() << "."
            << ::testing::UnitTest::GetInstance()->current_test_info()->name() << " " << what
            << ": max error " << d.maxError << ", max error/bound " << d.maxRatio << " (t = " << d.timeOfMaxRatio
            << ")\n";
}

// Compares column `name` with exact(t) at every output time: |value − exact(t)| ≤ bound(t).
// Reports the first few violations in detail, then only counts them.
inline Deviation compareColumn(const RunResult& r, const std::string& name, const std::function<double(double)>& exact,
                               const std::function<double(double)>& bound) {
  Deviation d;
  const auto& t = r.time();
  const auto& v = r.col(name);
  int failures = 0;
  for (std::size_t i = 0; i < v.size() && i < t.size(); ++i) {
    double err = std::fabs(v[i] - exact(t[i]));
    double b = bound(t[i]);
    double ratio = err / b;
    if (!(err <= b)) {  // also catches nan
      if (++failures <= 5)
        ADD_FAILURE() << name << " at t = " << t[i] << ": got " << num(v[i]) << ", expected " << num(exact(t[i]))
                      << ", error " << err << " > bound " << b;
      ratio = std::isnan(err) ? INFINITY : ratio;
    }
    d.maxError = std::max(d.maxError, std::isnan(err) ? INFINITY : err);
    if (ratio > d.maxRatio) {
      d.maxRatio = ratio;
      d.timeOfMaxRatio = t[i];
    }
  }
  if (failures > 5) ADD_FAILURE() << name << ": " << failures << " output times out of bound in all";
  report(name, d);
  return d;
}

// The error bound for an oscillation of amplitude A and period P integrated at relative tolerance
// rtol (atol = rtol × scale_i, the scale being about A): IDA keeps each step's estimated local error
// within rtol·|y_i| + atol_i ≤ 2·rtol·A (WRMS norm ≤ 1). BDF's local errors add up to a phase error
// that grows about linearly with the number of periods: measured for the runs of these tests
// (rtol 1e-6 to 1e-9) at 2–35 rtol·A per period. The ratio grows as rtol shrinks (the global error
// goes as about rtol^0.8; the stiff oscillator reaches 70 at rtol 1e-10), so the tests stay at
// rtol ≥ 1e-9. We allow kPhaseFactor = 100 rtol·A per period elapsed, plus one period's worth at
// the start, so a violation means an error beyond what the tolerance explains (a frequency wrong
// by 0.1 % gives 6e-3·A per period, 60× this bound at rtol 1e-6).
constexpr double kPhaseFactor = 100;
inline double oscillationBound(double rtol, double amplitude, double period, double t) {
  return kPhaseFactor * rtol * amplitude * (1 + t / period);
}

// The largest |c(t) − c(t0)| of a column that should be constant (a first integral).
inline double drift(const RunResult& r, const std::string& name) {
  const auto& v = r.col(name);
  double d = 0;
  for (double x : v) d = std::max(d, std::isnan(x) ? INFINITY : std::fabs(x - v.front()));
  return d;
}

// Times where column x crosses zero upwards, each located on the cubic Hermite interpolant of x and
// its derivative column v between two output times (error O(h⁴), far below the tolerances here).
inline std::vector<double> upwardZeroCrossings(const RunResult& r, const std::string& x, const std::string& v) {
  const auto &t = r.time(), &xs = r.col(x), &vs = r.col(v);
  std::vector<double> crossings;
  for (std::size_t i = 0; i + 1 < xs.size() && i + 1 < vs.size(); ++i) {
    if (!(xs[i] < 0 && xs[i + 1] >= 0)) continue;
    const double h = t[i + 1] - t[i];
    auto hermite = [&](double s) {
      const double s2 = s * s, s3 = s2 * s;
      return (2 * s3 - 3 * s2 + 1) * xs[i] + (s3 - 2 * s2 + s) * h * vs[i] + (-2 * s3 + 3 * s2) * xs[i + 1] +
             (s3 - s2) * h * vs[i + 1];
    };
    double lo = 0, hi = 1;
    for (int k = 0; k < 60; ++k) (hermite(0.5 * (lo + hi)) < 0 ? lo : hi) = 0.5 * (lo + hi);
    crossings.push_back(t[i] + 0.5 * (lo + hi) * h);
  }
  return crossings;
}

}  // namespace qdot::simtest
