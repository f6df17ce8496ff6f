#include <ssx/error.hpp>

#include <algorithm>
#include <cctype>

namespace ssx {

namespace {

// single-character insertions, deletions, substitutions and swaps of neighbours (optimal string
// alignment), case ignored
std::size_t editDistance(std::string_view a, std::string_view b) {
  const auto same = [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  };
  const std::size_t w = b.size() + 1;
  std::vector<std::size_t> d((a.size() + 1) * w);
  for (std::size_t i = 0; i <= a.size(); ++i) d[i * w] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t v = std::min({d[(i - 1) * w + j] + 1, d[i * w + j - 1] + 1,
                                d[(i - 1) * w + j - 1] + (same(a[i - 1], b[j - 1]) ? 0 : 1)});
      if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1])) v = std::min(v, d[(i - 2) * w + j - 2] + 1);
      d[i * w + j] = v;
    }
  return d[a.size() * w + b.size()];
}

}  // namespace

std::string nearestName(std::string_view name, const std::vector<std::string>& candidates) {
  const std::size_t allowed = std::max<std::size_t>(1, name.size() / 3);
  const std::string* best = nullptr;
  std::size_t best_distance = allowed + 1;
  for (const auto& c : candidates) {
    if (c == name) continue;
    const std::size_t d = editDistance(name, c);
    if (d < best_distance) {
      best_distance = d;
      best = &c;
    }
  }
  return best != nullptr ? *best : std::string();
}

std::string didYouMean(std::string_view name, const std::vector<std::string>& candidates) {
  const std::string best = nearestName(name, candidates);
  return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
}

std::string SourceLocation::str() const {
  if (file.empty()) return "<code>";
  if (line <= 0) return file;
  return file + ":" + std::to_string(line);
}

ConfigError::ConfigError(SourceLocation where, const std::string& message)
    : Error(where.str() + ": error: " + message), where_(std::move(where)), detail_(message) {}

StepError::StepError(std::string artifact, std::string plugin, std::int64_t step, const std::string& what)
    : Error("step " + std::to_string(step) + ": artifact '" + artifact + "', " + plugin + ": " + what),
      artifact_(std::move(artifact)),
      plugin_(std::move(plugin)),
      step_(step) {}

}  // namespace ssx
