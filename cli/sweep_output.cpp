// The results file of a sweep: a fingerprint line, a header, then one row per run as runs finish,
// each flushed; resuming skips what is there. And the per-point summary (see sweep.hpp).
#include "sweep.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>

namespace ssx::sweep {

namespace {

std::string join(const std::vector<std::string>& fields) {
  std::string out;
  for (std::size_t i = 0; i < fields.size(); ++i) out += (i ? "," : "") + csvField(fields[i]);
  return out;
}

const char* kRobotHeader = "run,robot,tracking_error_mean,tracking_error_max,min_distance";

// the lines of a file, without a last line that has no newline (a write cut short); `keep`
// receives the byte count of the complete lines
std::vector<std::string> completeLines(const fs::path& file, std::uintmax_t& keep) {
  std::ifstream in(file, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto last = text.rfind('\n');
  keep = last == std::string::npos ? 0 : last + 1;
  std::vector<std::string> lines;
  for (std::size_t b = 0; b < keep;) {
    const auto e = text.find('\n', b);
    lines.push_back(text.substr(b, e - b));
    b = e + 1;
  }
  return lines;
}

// a run's number as a row writes it (decimal digits), or nothing
std::optional<std::int64_t> runNumber(const std::string& text) {
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || v < 0) return std::nullopt;
  return v;
}

void check(std::FILE* f, const fs::path& file) {
  if (std::fflush(f) != 0 || std::ferror(f) != 0)
    throw std::runtime_error("writing '" + file.string() + "' failed: " + std::strerror(errno) + " (disk full?)");
}

}  // namespace

Output::Output(const Spec& spec, fs::path file, fs::path robots_file)
    : spec_(spec), file_(std::move(file)), robots_file_(std::move(robots_file)) {
  // the sweep's outputs are none of its inputs (the sweep file, the scene and every file the scene
  // reads) nor each other, before any is opened
  {
    RunFiles files;
    files.addInput(spec.file);
    files.addInput(spec.scene);
    try {
      SceneOptions options;
      options.plugin_path = spec.plugin_path;
      options.max_input_bytes = spec.max_input_bytes;
      for (const fs::path& f : parseScene(spec.scene, options).files) files.addInput(f);
    } catch (const SceneError&) {
      // (the runs report the scene's problems, each in its row)
    }
    fs::path summary = file_;
    summary.replace_extension(".summary.csv");
    std::string problem = files.claimOutput(file_, "--out");
    if (problem.empty() && !robots_file_.empty()) problem = files.claimOutput(robots_file_, "--robots");
    if (problem.empty()) problem = files.claimOutput(summary, "the summary", true);
    if (!problem.empty()) throw std::runtime_error(problem);
  }
  done_.assign(static_cast<std::size_t>(spec.runCount()), false);
  const std::string fingerprint = "# ssx sweep " + spec.fingerprint + " runs " + std::to_string(spec.runCount());
  const std::string header = join(spec.columns());
  std::error_code ec;
  const bool resume = fs::exists(file_, ec) && fs::file_size(file_, ec) > 0;
  if (resume) {
    std::uintmax_t keep = 0;
    const auto lines = completeLines(file_, keep);
    if (lines.size() < 2 || lines[0] != fingerprint || lines[1] != header)
      throw std::runtime_error("'" + file_.string() +
                               "' holds the results of another sweep (or this sweep file or its scene changed since); "
                               "give another --out, or remove it to start again");
    fs::resize_file(file_, keep);  // a row cut short is run again
    const std::size_t columns = spec.columns().size();
    for (std::size_t i = 2; i < lines.size(); ++i) {
      if (lines[i].find_first_not_of(" \t\r") == std::string::npos) continue;  // a blank line (an editor's)
      auto fields = csvSplit(lines[i]);
      const auto run = runNumber(fields.at(0));
      if (!run || fields.size() != columns)
        throw std::runtime_error("'" + file_.string() + "' line " + std::to_string(i + 1) +
                                 " is no row of this sweep (" +
                                 (!run ? "its first field '" + fields.at(0) + "' is no run number"
                                       : std::to_string(fields.size()) + " fields, the header has " +
                                             std::to_string(columns)) +
                                 "): mend or remove that line, or give another --out");
      if (*run >= spec.runCount() || done_[static_cast<std::size_t>(*run)]) continue;
      done_[static_cast<std::size_t>(*run)] = true;
      rows_.push_back(std::move(fields));
    }
  }
  out_ = ssx::openOutputFile(file_, resume);  // (locked: a second sweep writing it is refused)
  if (!resume) {
    std::fprintf(out_, "%s\n%s\n", fingerprint.c_str(), header.c_str());
    check(out_, file_);
  }
  if (!robots_file_.empty()) {
    // rows of runs the results file does not hold (cut short before their row) are dropped
    std::vector<std::string> kept;
    if (resume && fs::exists(robots_file_, ec)) {
      std::uintmax_t keep = 0;
      for (const auto& line : completeLines(robots_file_, keep)) {
        if (line == kRobotHeader) continue;
        // (a line that is no row of a run the results hold is dropped: those runs are run again)
        const auto run = runNumber(line.substr(0, line.find(',')));
        if (run && *run < spec.runCount() && done_[static_cast<std::size_t>(*run)]) kept.push_back(line);
      }
    }
    robots_ = ssx::openOutputFile(robots_file_);
    std::fprintf(robots_, "%s\n", kRobotHeader);
    for (const auto& line : kept) std::fprintf(robots_, "%s\n", line.c_str());
    check(robots_, robots_file_);
  }
  pending_ = static_cast<std::int64_t>(std::count(done_.begin(), done_.end(), false));
}

Output::~Output() {
  if (out_ != nullptr) std::fclose(out_);
  if (robots_ != nullptr) std::fclose(robots_);
}

void Output::write(const Result& r) {
  const auto t0 = std::chrono::steady_clock::now();
  if (robots_ != nullptr) {
    for (const auto& line : r.robots) std::fprintf(robots_, "%s\n", line.c_str());
    check(robots_, robots_file_);
  }
  std::fprintf(out_, "%s\n", r.row.c_str());
  check(out_, file_);
  done_[static_cast<std::size_t>(r.run)] = true;
  --pending_;
  rows_.push_back(csvSplit(r.row));
  write_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
}

double Output::writeMedianMs() const {
  if (write_ms_.empty()) return 0;
  std::vector<double> v = write_ms_;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

fs::path Output::writeSummary() const {
  const auto columns = spec_.columns();
  const auto metrics = spec_.metricColumns();
  const std::size_t status_col = 3 + spec_.parameters.size();
  std::vector<std::string> header{"point"};
  for (const auto& p : spec_.parameters) header.push_back(p.name);
  header.insert(header.end(), {"runs", "ok", "failed"});
  for (const auto& m : metrics)
    if (m != "state_hash")
      for (const char* s : {"_mean", "_std", "_min", "_max"}) header.push_back(m + s);
  // per point, per metric: the values of its ok runs
  std::map<std::size_t, std::vector<std::vector<double>>> values;
  std::map<std::size_t, std::pair<std::int64_t, std::int64_t>> counts;  // runs, ok
  for (const auto& row : rows_) {
    if (row.size() != columns.size()) continue;
    const std::size_t point = std::stoull(row[1]);
    auto& c = counts[point];
    ++c.first;
    auto& v = values[point];
    v.resize(metrics.size());
    if (row[status_col] != "ok") continue;
    ++c.second;
    for (std::size_t m = 0; m < metrics.size(); ++m) {
      const std::string& f = row[status_col + 1 + m];
      if (metrics[m] == "state_hash" || f.empty()) continue;
      v[m].push_back(std::stod(f));
    }
  }
  fs::path file = file_;
  file.replace_extension(".summary.csv");
  const fs::path partial = file.string() + ".partial";
  std::FILE* f = ssx::openOutputFile(partial);
  std::fprintf(f, "%s\n", join(header).c_str());
  for (std::size_t point = 0; point < spec_.points.size(); ++point) {
    std::vector<std::string> line{std::to_string(point)};
    line.insert(line.end(), spec_.points[point].begin(), spec_.points[point].end());
    const auto c = counts[point];
    line.insert(line.end(), {std::to_string(c.first), std::to_string(c.second), std::to_string(c.first - c.second)});
    auto& v = values[point];
    v.resize(metrics.size());
    for (std::size_t m = 0; m < metrics.size(); ++m) {
      if (metrics[m] == "state_hash") continue;
      const auto& x = v[m];
      if (x.empty()) {
        line.insert(line.end(), 4, "");
        continue;
      }
      double mean = 0;
      for (double d : x) mean += d;
      mean /= static_cast<double>(x.size());
      double var = 0;
      for (double d : x) var += (d - mean) * (d - mean);
      const double sd = x.size() > 1 ? std::sqrt(var / static_cast<double>(x.size() - 1)) : 0.0;
      line.insert(line.end(), {number(mean), number(sd), number(*std::min_element(x.begin(), x.end())),
                               number(*std::max_element(x.begin(), x.end()))});
    }
    std::fprintf(f, "%s\n", join(line).c_str());
  }
  const bool ok = std::fflush(f) == 0 && std::ferror(f) == 0;
  std::fclose(f);
  if (!ok || std::rename(partial.c_str(), file.c_str()) != 0) {
    std::remove(partial.c_str());
    throw std::runtime_error("writing '" + file.string() + "' failed (disk full?)");
  }
  return file;
}

}  // namespace ssx::sweep
