// A one-to-one assignment of rows to columns under a gate: the most pairs whose cost is finite,
// and among those the least summed cost. Scoring (detections to ground truth) and a season's
// association (fruitlets of one visit to the next) both need it.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace fvp::host {

/// The most columns an assignment handles exactly (dynamic programming over subsets of the
/// columns); beyond, pairs are taken greedily by cost. A cluster holds 3-8 fruitlets.
inline constexpr std::size_t kExactAssignmentMaxColumns = 16;
/// The most cells, (rows + 1) * 2^columns, of the exact search (about 20 bytes each): beyond,
/// greedy too, so no input can ask for gigabytes.
inline constexpr std::size_t kExactAssignmentMaxCells = std::size_t{1} << 22;

/// column_of_row[r]: the column assigned to row r, or -1. cost(r, c) is +inf or NaN for a
/// pair the gate refuses. Exact up to kExactAssignmentMaxColumns columns and
/// kExactAssignmentMaxCells cells.
std::vector<int> assignOneToOne(std::size_t rows, std::size_t columns,
                                const std::function<double(std::size_t, std::size_t)>& cost);

}  // namespace fvp::host
