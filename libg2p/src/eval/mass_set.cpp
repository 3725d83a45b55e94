// mass_set: mass errors over a CSV of predictions (`g2p eval mass`).
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "g2p/eval.h"

namespace g2p {

Result<MassErrors> mass_errors_from_csv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.rfind("object,predicted_kg,true_kg", 0) != 0)
    return Status::ParseError(path + ":1: the header must start object,predicted_kg,true_kg");
  std::vector<double> predicted, truth;
  for (int n = 2; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::stringstream row(line);
    std::string name, p, t;
    std::getline(row, name, ',');
    std::getline(row, p, ',');
    std::getline(row, t, ',');
    char* end_p = nullptr;
    char* end_t = nullptr;
    const double pv = std::strtod(p.c_str(), &end_p), tv = std::strtod(t.c_str(), &end_t);
    if (end_p == p.c_str() || *end_p != '\0' || end_t == t.c_str() || *end_t != '\0')
      return Status::ParseError(path + ":" + std::to_string(n) + ": expected two numbers, got '" + line + "'");
    predicted.push_back(pv);
    truth.push_back(tv);
  }
  Result<MassErrors> e = mass_errors(predicted, truth);
  if (!e.ok()) return Status(e.status().code(), path + ": " + e.status().message());
  return e;
}

std::string mass_errors_json(const MassErrors& e) {
  const nlohmann::json j = {
      {"objects", e.objects}, {"ade_kg", e.ade_kg}, {"alde", e.alde}, {"ape", e.ape}, {"mnre", e.mnre}};
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace g2p
