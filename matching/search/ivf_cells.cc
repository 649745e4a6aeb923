#include "matching/search/ivf_cells.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

#include "matching/search/approximate_engine.h"

namespace openable {

std::unique_ptr<IvfCells> MakeIvfCells(const cv::Mat& references, const cv::Mat& centres,
                                       const std::vector<std::vector<int>>& cells) {
  if (centres.rows != static_cast<int>(cells.size()) || centres.cols != references.cols ||
      centres.depth() != CV_8U)
    throw std::invalid_argument("IVF cells: " + std::to_string(centres.rows) + " centres of " +
                                std::to_string(centres.cols) + " bytes for " +
                                std::to_string(cells.size()) + " cells of rows of " +
                                std::to_string(references.cols) + " bytes");
  auto out = std::make_unique<IvfCells>();
  out->centres = std::make_unique<HammingReferences>(centres);
  out->rows.resize(cells.size());
  out->offsets.assign(cells.size() + 1, 0);
  for (std::size_t c = 0; c < cells.size(); ++c)
    out->offsets[c + 1] = out->offsets[c] + static_cast<std::uint32_t>(cells[c].size());
  out->owned_ids.reserve(out->offsets.back());
  for (const std::vector<int>& ids : cells)
    out->owned_ids.insert(out->owned_ids.end(), ids.begin(), ids.end());
  out->ids = out->owned_ids.data();
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(references.rows), 0);
  std::int64_t total = 0;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const std::vector<int>& ids = cells[c];
    total += static_cast<std::int64_t>(ids.size());
    if (ids.empty()) continue;
    cv::Mat rows(static_cast<int>(ids.size()), references.cols, CV_8U);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const int id = ids[i];
      if (id < 0 || id >= references.rows || seen[static_cast<std::size_t>(id)])
        throw std::invalid_argument(
            "IVF cells: row " + std::to_string(id) +
            (id < 0 || id >= references.rows
                 ? " is not one of the " + std::to_string(references.rows) + " references"
                 : " is in two cells"));
      seen[static_cast<std::size_t>(id)] = 1;
      references.row(id).copyTo(rows.row(static_cast<int>(i)));
    }
    out->rows[c] = std::make_unique<HammingReferences>(rows);
  }
  if (total != references.rows)
    throw std::invalid_argument("IVF cells: they hold " + std::to_string(total) +
                                " rows, expected " + std::to_string(references.rows));
  return out;
}

CandidateLists SearchIvfCells(const IvfCells& cells, const cv::Mat& queries, int k, int nprobe,
                              int threads) {
  CandidateLists out(static_cast<size_t>(queries.rows));
  const int lists = cells.Cells();
  const int probes = std::min(nprobe, lists);
  ParallelBlocks(queries.rows, kQueryBlock, threads, [&](int q0, int q1) {
    std::vector<float> centre(static_cast<size_t>(lists)), d;
    std::vector<int> order(static_cast<size_t>(lists));
    for (int q = q0; q < q1; ++q) {
      const std::uint8_t* query = queries.ptr<std::uint8_t>(q);
      cells.centres->Distances(query, centre.data());
      std::iota(order.begin(), order.end(), 0);
      std::partial_sort(order.begin(), order.begin() + probes, order.end(), [&](int a, int b) {
        return centre[static_cast<size_t>(a)] < centre[static_cast<size_t>(b)] ||
               (centre[static_cast<size_t>(a)] == centre[static_cast<size_t>(b)] && a < b);
      });
      // The k nearest rows of the probed cells in a max-heap of k.
      std::vector<Candidate>& heap = out[static_cast<size_t>(q)];
      heap.reserve(static_cast<size_t>(k));
      for (int p = 0; p < probes; ++p) {
        const int l = order[static_cast<size_t>(p)];
        const int count = cells.Count(l);
        if (count == 0) continue;
        const std::int32_t* ids = cells.Ids(l);
        d.resize(static_cast<std::size_t>(count));
        cells.rows[static_cast<size_t>(l)]->Distances(query, d.data());
        for (int i = 0; i < count; ++i) {
          const Candidate c{ids[i], d[i]};
          if (static_cast<int>(heap.size()) < k) {
            heap.push_back(c);
            std::push_heap(heap.begin(), heap.end(), CandidateBefore);
          } else if (CandidateBefore(c, heap.front())) {
            std::pop_heap(heap.begin(), heap.end(), CandidateBefore);
            heap.back() = c;
            std::push_heap(heap.begin(), heap.end(), CandidateBefore);
          }
        }
      }
      SortCandidates(heap);
    }
  });
  return out;
}

}  // namespace openable
