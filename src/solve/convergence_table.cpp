#include "fictus/solve/convergence_table.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace fictus {

namespace {
std::array<double, 3> errors_of(const LevelResult& r) { return {r.l2_omega, r.h1_omega, r.l2_gamma}; }

std::string printf_string(const char* format, auto... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, format, args...);
  return buffer;
}
}  // namespace

std::vector<std::array<double, 3>> observed_rates(const std::vector<LevelResult>& rows) {
  std::vector<std::array<double, 3>> rates;
  for (std::size_t k = 0; k + 1 < rows.size(); ++k) {
    const auto a = errors_of(rows[k]), b = errors_of(rows[k + 1]);
    const double ratio = std::log2(double(rows[k + 1].N) / rows[k].N);
    rates.push_back({std::log2(a[0] / b[0]) / ratio, std::log2(a[1] / b[1]) / ratio, std::log2(a[2] / b[2]) / ratio});
  }
  return rates;
}

std::array<double, 3> fitted_rates(const std::vector<LevelResult>& rows) {
  std::array<double, 3> slope{};
  const double n = double(rows.size());
  if (rows.size() < 2) return slope;
  for (int c = 0; c < 3; ++c) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const LevelResult& r : rows) {
      const double x = std::log(double(r.N)), y = -std::log(errors_of(r)[c]);
      sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    slope[c] = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  }
  return slope;
}

std::optional<std::array<double, 3>> paper_rates_over(Variant variant, const std::vector<LevelResult>& rows) {
  std::vector<LevelResult> paper;
  for (const LevelResult& r : rows)
    if (const std::optional<PaperRow> p = paper_row(variant, r.N))
      paper.push_back({.N = p->N, .l2_omega = p->l2_omega, .h1_omega = p->h1_omega, .l2_gamma = p->l2_gamma});
  if (paper.size() < 2) return std::nullopt;
  if (paper.size() == paper_table(variant).size()) return paper_rates(variant);
  return fitted_rates(paper);
}

std::string format_convergence_table(const std::string& title, const std::vector<LevelResult>& rows,
                                     std::optional<Variant> paper_variant) {
  std::string out = title + "\n";
  out += printf_string("%-7s %-14s | %-9s %9s %9s %9s %9s | %-8s %8s %9s %9s %9s\n", "h", "n/m", "it0/it1", "time[s]",
                       "L2(w)", "H1(w)", "L2(g)", "paper", "time[s]", "L2(w)", "H1(w)", "L2(g)");
  for (const LevelResult& r : rows) {
    out += printf_string("1/%-5d %-14s | %-9s %9.3f %9.2e %9.2e %9.2e |", r.N,
                         (std::to_string(r.n_nodes) + "/" + std::to_string(r.m)).c_str(),
                         (std::to_string(r.it0) + "/" + std::to_string(r.it1)).c_str(), r.time, r.l2_omega, r.h1_omega,
                         r.l2_gamma);
    std::optional<PaperRow> p = paper_variant ? paper_row(*paper_variant, r.N) : std::nullopt;
    if (p)
      out += printf_string(" %-8s %8.1f %9.2e %9.2e %9.2e\n",
                           (std::to_string(p->it0) + "/" + std::to_string(p->it1)).c_str(), p->time, p->l2_omega,
                           p->h1_omega, p->l2_gamma);
    else
      out += "\n";
  }
  const auto rates = observed_rates(rows);
  for (std::size_t k = 0; k < rates.size(); ++k)
    out += printf_string("rate 1/%d->1/%d %*s %9.2f %9.2f %9.2f |\n", rows[k].N, rows[k + 1].N,
                         int(34 - std::to_string(rows[k].N).size() - std::to_string(rows[k + 1].N).size()), "",
                         rates[k][0], rates[k][1], rates[k][2]);
  if (rows.size() >= 2) {
    const auto fit = fitted_rates(rows);
    out += printf_string("%-44s %9.2f %9.2f %9.2f |", "rates (least-squares fit)", fit[0], fit[1], fit[2]);
    if (const auto pr = paper_variant ? paper_rates_over(*paper_variant, rows) : std::nullopt)
      out += printf_string(" %-8s %8s %9.2f %9.2f %9.2f", "paper", "", (*pr)[0], (*pr)[1], (*pr)[2]);
    out += "\n";
  }
  return out;
}

}  // namespace fictus
