// What the SNAPS chain reports and writes: the text report, the JSON figures and the output
// files of Snaps_output_name.
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "OpenABLE/app/snaps_chain.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/reports/figures.h"
#include "OpenABLE/snaps/plot.h"

namespace openable::snaps {
namespace {

// The SNAPS figures, in text and JSON alike: 6 significant digits.
std::string Number(double v) { return FormatNumber(v); }
Json JsonNumber(double v) { return json::Number(v, 6); }

Json StatsJson(const LatencyStats& s) {
  return {
      {"count", s.count},          {"mean_s", JsonNumber(s.mean)},     {"min_s", JsonNumber(s.min)},
      {"q1_s", JsonNumber(s.q1)},  {"median_s", JsonNumber(s.median)}, {"q3_s", JsonNumber(s.q3)},
      {"max_s", JsonNumber(s.max)}};
}

Json ErrorJson(const TrajectoryError& e) {
  return {{"rmse_m", JsonNumber(e.rmse)},
          {"mean_m", JsonNumber(e.mean)},
          {"median_m", JsonNumber(e.median)},
          {"max_m", JsonNumber(e.max)}};
}

std::string StatsLine(const LatencyStats& s) {
  char b[200];
  std::snprintf(
      b, sizeof b, "%6d  mean %9.3f ms  [min %.3f, q1 %.3f, median %.3f, q3 %.3f, max %.3f] ms",
      s.count, s.mean * 1e3, s.min * 1e3, s.q1 * 1e3, s.median * 1e3, s.q3 * 1e3, s.max * 1e3);
  return b;
}

std::string CsvOfLoops(const Trajectory& t, const std::vector<LoopPair>& loops) {
  std::ostringstream o;
  o << "# query_frame,reference_frame,similarity (frame numbers of the trajectory)\n";
  for (const auto& l : loops)
    o << t.frame_ids[static_cast<size_t>(l.query)] << ","
      << t.frame_ids[static_cast<size_t>(l.reference)] << "," << Number(l.similarity) << "\n";
  return o.str();
}

// The search's latencies: without a loop, with one found, all, the corrections, the
// thumbnails.
struct SearchLatencies {
  LatencyStats none, found, all, correction, thumbnail;
};

SearchLatencies LatenciesOf(const ImageSearchResult& searched) {
  std::vector<double> none, found, all;
  for (const auto& s : searched.steps) {
    all.push_back(s.seconds);
    (s.loop ? found : none).push_back(s.seconds);
  }
  return {Summarize(none), Summarize(found), Summarize(all), Summarize(searched.correction_seconds),
          Summarize(searched.thumbnail_seconds)};
}

// Snaps_loops pairs, matrix and openable: what became of the pairs of the file, or of the
// matrix's matches, when their frames were mapped to the trajectory's poses (keyframes).
bool HasPairCounts(const Config& c) {
  return c.snaps.loops == LoopSource::kPairs || c.snaps.loops == LoopSource::kMatrix ||
         c.snaps.loops == LoopSource::kOpenable;
}

std::string PairCountsLine(const Config& c, const ChainResult& r) {
  const PairCounts& n = r.pairs;
  const int tolerance = c.snaps.keyframe_tolerance;
  std::ostringstream o;
  if (c.snaps.loops == LoopSource::kPairs)
    o << "pairs file: " << n.Total() << " pairs: ";
  else if (r.verified_loops)
    o << "verified loops: " << n.Total() << " queries answered by geometric verification: ";
  else
    o << "matrix: " << n.Total() << " matches below " << Number(c.snaps.matrix_threshold) << ": ";
  o << n.on_poses << " on keyframes, " << n.associated;
  if (r.loops_by_time)
    o << " associated by time (frames of a bag, Snaps_time_tolerance "
      << Number(c.snaps.time_tolerance) << " s), ";
  else if (tolerance > 0)
    o << " associated to the nearest keyframe within +-" << tolerance
      << (tolerance == 1 ? " frame, " : " frames, ");
  else
    o << " associated (Snaps_keyframe_tolerance 0), ";
  o << n.dropped << " dropped";
  if (n.outside > 0) o << ", " << n.outside << " outside the trajectory dropped";
  if (c.snaps.loops == LoopSource::kPairs && c.snaps.middle_of_runs)
    o << "; the middle reference of each run kept";
  if (n.merged > 0)
    o << "; " << n.merged << " merged (one loop per query keyframe, the most similar)";
  return o.str();
}

Json PairCountsJson(const Config& c, const PairCounts& n) {
  return {{"keyframe_tolerance", c.snaps.keyframe_tolerance},
          {"total", n.Total()},
          {"on_poses", n.on_poses},
          {"associated", n.associated},
          {"dropped", n.dropped},
          {"outside", n.outside},
          {"merged", n.merged}};
}

}  // namespace

namespace {

// The change from `before` to `after` in percent, signed and rounded to 0.1: "+8.1 %".
std::string SignedPercent(double after, double before) {
  const double change = 100.0 * (after - before) / before;
  return (change >= 0 ? "+" : "") + FormatFixed(change, 1) + " %";
}

// What the error table means, in words, when it can mislead: a correction that raises the
// unaligned error while lowering the aligned one, and an input that cannot be the ground
// truth's route (its aligned error a large part of the route's extent): wrong conventions
// rather than drift.
std::vector<std::string> ErrorReading(const ChainResult& r) {
  std::vector<std::string> lines;
  const ChainErrors& input = r.errors.front();
  for (size_t i = 1; i < r.errors.size(); ++i) {
    const ChainErrors& e = r.errors[i];
    if (e.raw.mean > input.raw.mean && e.aligned.mean < input.aligned.mean) {
      lines.push_back("Read: " + e.name +
                      " makes the route's shape closer to the ground truth (aligned "
                      "error " +
                      FormatFixed(input.aligned.mean, 2) + " -> " + FormatFixed(e.aligned.mean, 2) +
                      " m) but moves it as a whole (unaligned " + FormatFixed(input.raw.mean, 2) +
                      " -> " + FormatFixed(e.raw.mean, 2) +
                      " m): loops fix the shape, not where the start and its "
                      "heading sit; the aligned columns measure the shape.");
      break;
    }
  }
  // An input too far from the ground truth's route to be a drifting estimate of it
  // (ConventionHint): the reading above would mislead, only the hint is given.
  if (const std::string hint = ConventionHint(input.aligned, r.truth); !hint.empty())
    lines = {"Hint: " + hint};
  return lines;
}

}  // namespace

std::string FormatChainReport(const Config& c, const ChainResult& r) {
  const SnapsOptions& s = c.snaps;
  const std::string source = EnumName(s.loops);
  std::ostringstream out;
  out << "openable_snaps " << kVersion << ": " << r.input.Size() << " poses ("
      << TrajectoryFormatName(r.input.format) << ", frames " << r.input.frame_ids.front() << "-"
      << r.input.frame_ids.back() << ") from "
      << (r.computed ? r.trajectory_name : "\"" + r.trajectory_name + "\"") << "\n";
  if (r.computed)
    out << "  odometry: " << r.odometry.kind << ", scale from " << r.odometry.scale << "; "
        << r.odometry.failed << " failed steps (kept the previous motion)"
        << (r.odometry.failed ? ", first " + r.odometry.first_failure : std::string())
        << "\n  odometry per frame " << StatsLine(Summarize(r.odometry.seconds))
        << " (paper: 0.295 s per frame with loop closure)\n";
  out << "  loops: " << r.loops.size() << " pairs from " << source << " (" << Number(r.loop_seconds)
      << " s)";
  if (r.discounted_ran)
    out << "; discounted update closes " << r.closed.size() << " (pause " << s.search.discount.pause
        << ", K " << s.search.discount.discount_length << ")";
  out << "\n";
  if (HasPairCounts(c)) out << "  " << PairCountsLine(c, r) << "\n";
  if (r.graph_ran)
    out << "  pose graph: " << r.graph_report.loop_edges << " loop edges, "
        << r.graph_report.iterations << " iterations, cost " << Number(r.graph_report.initial_cost)
        << " -> " << Number(r.graph_report.final_cost) << ", " << Number(r.graph_report.seconds)
        << " s" << (r.graph_report.converged ? "" : " (not converged: max iterations)") << "\n";
  if (r.evaluated) {
    out << "Absolute trajectory error against \"" << s.ground_truth << "\" (metres):\n"
        << "  trajectory      mean dev.      RMSE       max   | aligned: mean dev.   RMSE\n";
    const double input_mean = r.errors.front().raw.mean;
    for (size_t i = 0; i < r.errors.size(); ++i) {
      const ChainErrors& e = r.errors[i];
      char line[200];
      std::snprintf(line, sizeof line, "  %-12s %10.3f %10.3f %9.3f   | %16.3f %8.3f",
                    e.name.c_str(), e.raw.mean, e.raw.rmse, e.raw.max, e.aligned.mean,
                    e.aligned.rmse);
      out << line;
      if (i > 0 && input_mean > 0) {
        const double aligned_input = r.errors.front().aligned.mean;
        out << "   (mean dev. " << SignedPercent(e.raw.mean, input_mean);
        if (aligned_input > 0) out << ", aligned " << SignedPercent(e.aligned.mean, aligned_input);
        out << ")";
      }
      out << "\n";
    }
    // Each reading wrapped at 92 columns.
    for (const std::string& reading : ErrorReading(r)) {
      std::istringstream words(reading);
      std::string word, line = " ";
      while (words >> word) {
        if (line.size() + word.size() + 1 > 92) {
          out << line << "\n";
          line = "   ";
        }
        line += " " + word;
      }
      out << line << "\n";
    }
  }
  if (s.loops == LoopSource::kSearch) {
    const SearchLatencies l = LatenciesOf(r.searched);
    out << "Latency per frame (paper, Fig. 5: no candidate 2.94e-6 s, loop closure 0.027 s):\n"
        << "  search, no loop    " << StatsLine(l.none) << "\n"
        << "  search, loop found " << StatsLine(l.found) << "\n"
        << "  correction (Eq. 6) " << StatsLine(l.correction) << "\n"
        << "  thumbnail (read)   " << StatsLine(l.thumbnail) << "\n";
  } else if (r.discounted_ran && !r.closed.empty()) {
    out << "  discounted update: " << FormatFixed(1e3 * r.discounted_seconds, 2) << " ms for "
        << r.closed.size() << " loops\n";
  }
  return ToValidUtf8(out.str());
}

Json ChainJson(const Config& c, const ChainResult& r) {
  const PoseGraphReport& g = r.graph_report;
  Json o;
  o["trajectory"] = r.trajectory_name;
  o["poses"] = r.input.Size();
  o["loop_source"] = EnumName(c.snaps.loops);
  o["loops"] = r.loops.size();
  if (HasPairCounts(c)) o["pairs"] = PairCountsJson(c, r.pairs);
  o["loops_closed_by_discounted_update"] = r.closed.size();
  o["pose_graph"] = {{"loop_edges", g.loop_edges},
                     {"iterations", g.iterations},
                     {"initial_cost", JsonNumber(g.initial_cost)},
                     {"final_cost", JsonNumber(g.final_cost)},
                     {"seconds", JsonNumber(g.seconds)}};
  if (r.evaluated) {
    Json& errors = o["errors"] = Json::object();
    for (const ChainErrors& e : r.errors)
      errors[e.name] = {{"unaligned", ErrorJson(e.raw)}, {"aligned", ErrorJson(e.aligned)}};
  }
  if (c.snaps.loops == LoopSource::kSearch) {
    const SearchLatencies l = LatenciesOf(r.searched);
    o["latency"] = {{"search_no_loop", StatsJson(l.none)},
                    {"search_loop_found", StatsJson(l.found)},
                    {"search_all", StatsJson(l.all)},
                    {"correction", StatsJson(l.correction)},
                    {"thumbnail", StatsJson(l.thumbnail)}};
  }
  if (r.computed)
    o["odometry"] = {{"kind", r.odometry.kind},
                     {"failed_steps", r.odometry.failed},
                     {"per_frame", StatsJson(Summarize(r.odometry.seconds))}};
  return o;
}

std::string EncodeChainJson(const Config& c, const ChainResult& r) {
  return json::Dump(ChainJson(c, r));
}

std::vector<std::string> WriteChainOutputs(const Config& c, const ChainResult& r) {
  const std::string& p = c.snaps.output_name;
  if (p.empty()) return {};
  const char* key = "Snaps_output_name";
  OutputBatch batch;
  if (r.discounted_ran) batch.Stage(key, p + "_discounted.txt", EncodeTrajectory(r.discounted));
  if (r.graph_ran) batch.Stage(key, p + "_pose_graph.txt", EncodeTrajectory(r.graph));
  if (r.computed) batch.Stage(key, p + "_odometry.txt", EncodeTrajectory(r.input));
  batch.Stage(key, p + "_loops.csv", CsvOfLoops(r.input, r.loops));
  batch.Stage(key, p + ".json", EncodeChainJson(c, r));
  // The plot: the pose graph's result (or the one corrector's), and the discounted update's
  // in a second figure when both ran.
  auto figure = [&](const Trajectory& corrected, const std::string& label) {
    TrajectoryPlot plot;
    plot.truth = r.evaluated ? &r.truth : nullptr;
    plot.input = &r.input;
    plot.corrected = &corrected;
    plot.corrected_label = label;
    plot.loops = r.loops;
    plot.axes = EnumName(c.snaps.axes);
    plot.title = "SNAPS, " + std::to_string(r.loops.size()) + " loops (" + EnumName(c.snaps.loops) +
                 "): " +
                 (r.computed ? r.trajectory_name
                             : std::filesystem::path(c.snaps.trajectory).filename().string());
    return EncodePng(RenderTrajectories(plot));
  };
  if (r.graph_ran) batch.Stage(key, p + ".png", figure(r.graph, "pose graph"));
  if (r.discounted_ran)
    batch.Stage(key, p + (r.graph_ran ? "_discounted.png" : ".png"),
                figure(r.discounted, "discounted update (Eq. 6)"));
  const std::vector<std::string> paths = batch.Paths();
  batch.Commit();
  return paths;
}

}  // namespace openable::snaps
