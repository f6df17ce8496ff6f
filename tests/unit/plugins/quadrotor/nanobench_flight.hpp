#pragma once
// A trimmed NanoBench flight (examples/fidelity_nanobench/data), every column by name, for the
// tests that check a Crazyflie model against the real vehicle's logs.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace ssx::test {

inline std::map<std::string, std::vector<double>> readNanobenchFlight(const std::string& name) {
  std::filesystem::path path(SSX_EXAMPLES_DIR);
  path /= "fidelity_nanobench/data";
  path /= name;
  path += ".csv";
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream h(line);
  for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
  std::map<std::string, std::vector<double>> out;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::size_t k = 0;
    for (std::string cell; std::getline(row, cell, ',') && k < header.size(); ++k)
      out[header[k]].push_back(std::stod(cell));
  }
  return out;
}

}  // namespace ssx::test
