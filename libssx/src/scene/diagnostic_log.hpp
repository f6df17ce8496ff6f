#pragma once
// The problems found while a scene is read and built, each stamped with where in the document it
// belongs, so that they are reported in document order: each element's reading problems, then its
// building problems, whichever of the two found them first.

#include <ssx/parameters.hpp>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace ssx::detail {

// stages, in document order: 0 the scene's settings; (1, 2j) extension j read, (1, 2j+1) built;
// (2, 2k) element k read, (2, 2k+1) built; 3 the checks at the end
constexpr std::int64_t documentStage(std::int64_t major, std::int64_t minor = 0) { return (major << 40) + minor; }

// where each part of the model was in the document: its reading stage (documentStage); a builder
// given none numbers the model's extensions and placements in their order
struct BuildOrder {
  std::vector<std::int64_t> extensions;  // per extension of the model
  std::vector<std::int64_t> placements;  // per placement of the model
  bool after_errors = false;  // the reader found errors (what needs the whole scene is not checked)
};

class DiagnosticLog {
 public:
  std::int64_t stage = 0;  // the stage of what is added next

  void add(Diagnostic d) {
    list_.push_back(std::move(d));
    stamps_.push_back(stage);
  }
  void error(const SourceLocation& where, std::string message) {
    add({Diagnostic::Severity::Error, where, std::move(message)});
  }
  void warning(const SourceLocation& where, std::string message) {
    add({Diagnostic::Severity::Warning, where, std::move(message)});
  }
  std::size_t errorCount() const {
    return static_cast<std::size_t>(std::count_if(
        list_.begin(), list_.end(), [](const Diagnostic& d) { return d.severity == Diagnostic::Severity::Error; }));
  }
  std::size_t size() const { return list_.size(); }
  const Diagnostic& operator[](std::size_t i) const { return list_[i]; }
  // moves another log's problems into this one, with their stamps
  void append(DiagnosticLog&& other) {
    for (std::size_t i = 0; i < other.list_.size(); ++i) {
      list_.push_back(std::move(other.list_[i]));
      stamps_.push_back(other.stamps_[i]);
    }
    other.list_.clear();
    other.stamps_.clear();
  }
  // every problem, in document order (those of one stage in the order found); the log is emptied
  std::vector<Diagnostic> take() {
    std::vector<std::size_t> order(list_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return stamps_[a] < stamps_[b]; });
    std::vector<Diagnostic> sorted;
    sorted.reserve(order.size());
    for (std::size_t i : order) sorted.push_back(std::move(list_[i]));
    list_.clear();
    stamps_.clear();
    return sorted;
  }

 private:
  std::vector<Diagnostic> list_;
  std::vector<std::int64_t> stamps_;  // per problem: its stage
};

}  // namespace ssx::detail
