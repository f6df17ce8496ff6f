#pragma once
// Which bodies are joined to each other, directly or through others: both engines skip contacts
// between them and solve them together. Labels are recomputed whole whenever joints come or go
// (union-find, linear in bodies and joints), so that letting go of a joint splits a chain again.

#include <cstddef>
#include <numeric>
#include <utility>
#include <vector>

namespace ssx::detail {

// label[i] becomes the lowest body joined to i (i itself when none). `pair(k)` gives joint k's two
// bodies; a negative one (the static world, or a joint no longer there) joins nothing.
template <class Pair>
void labelArticulations(std::vector<int>& label, std::size_t joints, Pair&& pair) {
  std::iota(label.begin(), label.end(), 0);
  auto find = [&label](int x) {
    while (label[static_cast<std::size_t>(x)] != x) {
      const int up = label[static_cast<std::size_t>(label[static_cast<std::size_t>(x)])];
      label[static_cast<std::size_t>(x)] = up;
      x = up;
    }
    return x;
  };
  for (std::size_t k = 0; k < joints; ++k) {
    const auto [a, b] = pair(k);
    if (a < 0 || b < 0) continue;
    const int ra = find(a), rb = find(b);
    // the lower root stays the root: a set's root is its lowest body
    if (ra != rb) label[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  }
  for (std::size_t i = 0; i < label.size(); ++i) label[i] = find(static_cast<int>(i));
}

}  // namespace ssx::detail
