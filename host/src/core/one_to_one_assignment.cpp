#include "fvp/host/core/one_to_one_assignment.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace fvp::host {
namespace {

/// Closest pairs first: for more columns than the exact search takes.
std::vector<int> greedyAssignment(std::size_t rows, std::size_t columns,
                                  const std::function<double(std::size_t, std::size_t)>& cost) {
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < columns; ++c)
      if (const double e = cost(r, c); std::isfinite(e)) pairs.emplace_back(e, r, c);
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> column_of_row(rows, -1);
  std::vector<char> column_used(columns, 0);
  for (const auto& [e, r, c] : pairs)
    if (column_of_row[r] < 0 && !column_used[c]) column_of_row[r] = int(c), column_used[c] = 1;
  return column_of_row;
}

}  // namespace

std::vector<int> assignOneToOne(std::size_t rows, std::size_t columns,
                                const std::function<double(std::size_t, std::size_t)>& cost) {
  std::vector<int> column_of_row(rows, -1);
  if (rows == 0 || columns == 0) return column_of_row;
  if (columns > kExactAssignmentMaxColumns || (rows + 1) > kExactAssignmentMaxCells >> columns)
    return greedyAssignment(rows, columns, cost);
  // Over the rows in order, with the set of columns taken: (pairs, summed cost).
  struct Cell {
    int pairs = -1;  // -1: not reachable
    double cost = 0.0;
  };
  const auto better = [](const Cell& a, const Cell& b) {
    return b.pairs < 0 || a.pairs > b.pairs || (a.pairs == b.pairs && a.cost < b.cost);
  };
  const std::size_t sets = std::size_t{1} << columns;
  std::vector<std::vector<Cell>> best(rows + 1, std::vector<Cell>(sets));
  std::vector<std::vector<int>> choice(rows + 1, std::vector<int>(sets, -1));
  best[0][0] = {0, 0.0};
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t s = 0; s < sets; ++s) {
      const Cell here = best[r][s];
      if (here.pairs < 0) continue;
      if (better(here, best[r + 1][s])) best[r + 1][s] = here, choice[r + 1][s] = -1;
      for (std::size_t c = 0; c < columns; ++c) {
        if (s & (std::size_t{1} << c)) continue;
        const double e = cost(r, c);
        if (!std::isfinite(e)) continue;
        const std::size_t t = s | (std::size_t{1} << c);
        const Cell paired{here.pairs + 1, here.cost + e};
        if (better(paired, best[r + 1][t])) best[r + 1][t] = paired, choice[r + 1][t] = int(c);
      }
    }
  std::size_t end = 0;
  for (std::size_t s = 0; s < sets; ++s)
    if (best[rows][s].pairs >= 0 && better(best[rows][s], best[rows][end])) end = s;
  for (std::size_t r = rows, s = end; r > 0; --r)
    if (const int c = choice[r][s]; c >= 0) {
      column_of_row[r - 1] = c;
      s &= ~(std::size_t{1} << c);
    }
  return column_of_row;
}

}  // namespace fvp::host
