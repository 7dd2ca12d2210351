#pragma once
// Output formats of the CLI: results.json (keys of docs/results.md), CSV tables, atomic writes.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fictus/convergence_table.hpp"
#include "fictus/fictitious_domain_solver.hpp"

namespace fictus::cli {

/// Every option of options.hpp in effect, by key (results.json's `options`).
nlohmann::json options_to_json(const Problem& problem, const SolverOptions& options);
/// The option descriptions (`fictus options --json`).
nlohmann::json options_schema_json();
nlohmann::json solution_to_json(const Problem& problem, const Solution& solution);
LevelResult level_result(const Solution& solution);

/// Writes `text` to `path` through a temporary file in the same folder and a rename, so a reader
/// never sees a half-written file and an old file survives a failed write.
void write_atomically(const std::filesystem::path& path, const std::string& text);
void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& writer);

std::string points_csv(const Solution& solution);
std::string levels_csv(const std::vector<LevelResult>& rows);

}  // namespace fictus::cli
