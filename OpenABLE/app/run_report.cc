#include <cstdio>
#include <sstream>

#include "OpenABLE/app/run.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/cluster/cluster.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/io/json.h"

namespace openable {

namespace {

// The engine of the approximate index a run used (auto resolved by the rows' type), or empty
// without Approximate_search (which runs on one descriptor).
std::string IndexUsed(const Config& c, const RunResult& r) {
  if (!c.scale.approximate_search || r.descriptors.size() != 1) return "";
  const int depth = r.descriptors.front().metric == Metric::kL2 ? CV_32F : CV_8U;
  return ResolvedEngine(c.scale.approximate.engine, depth);
}

}  // namespace

std::string FormatRunReport(const Config& config, const RunOutcome& outcome) {
  const Config& c = outcome.automatic ? outcome.automatic->config : config;
  const RunResult& r = outcome.result;
  const Evaluation* evaluation = outcome.evaluation.get();
  const int patch = c.descriptor.patch_size;
  const DescriptionOptions& d = c.description;
  std::ostringstream out;
  out << "OpenABLE " << kVersion << ": ";
  for (size_t k = 0; k < r.descriptors.size(); ++k) {
    const RunDescriptor& e = r.descriptors[k];
    out << (k ? " + " : "") << e.name << " (" << e.row_width
        << (e.metric == Metric::kL2   ? " floats, L2"
            : e.metric == Metric::kL1 ? " bytes, L1"
                                      : " bytes, Hamming")
        << (r.fusion_weights.empty() ? "" : ", weight " + FormatNumber(r.fusion_weights[k])) << ")";
  }
  out << ", " << (d.type == DescriptionType::kGlobal ? "global " : "grid ")
      << (d.type == DescriptionType::kGlobal
              ? std::to_string(patch) + "x" + std::to_string(patch)
              : std::to_string(d.grid_x) + "x" + std::to_string(d.grid_y) + " cells of " +
                    std::to_string(patch) + "x" + std::to_string(patch))
      << ", sequence length " << c.matching.sequence_length
      << (c.matching.sequence_length > 1 && c.matching.partial != SequencePartial::kAhead
              ? std::string(" (") + EnumName(c.matching.partial) + " partial)"
              : std::string())
      << (c.matching.contrast.enabled
              ? ", contrast enhancement +-" + std::to_string(c.matching.contrast.window)
              : std::string())
      << ", score " << EnumName(c.matching.score.kind)
      << (c.matching.score.kind == MatchScore::kRatio
              ? " (window +-" + std::to_string(c.matching.score.window) + ")"
              : std::string())
      << "\n";
  if (!r.camera.empty()) out << "  camera: " << r.camera << "\n";
  if (!r.cache.empty()) out << "  descriptor cache: " << r.cache << "\n";
  for (const auto& t : r.traversals) {
    out << "  " << t.key << ": " << t.frames << " frames of " << t.frame_size.width << "x"
        << t.frame_size.height << " from \"" << t.path << "\" (rows " << t.first_row << "-"
        << t.first_row + t.frames - 1 << ")\n";
    for (const auto& s : t.skipped) out << "    skipped: " << s << "\n";
  }
  const auto& tm = r.timings;
  out << "  mode: " << r.mode_reason;
  if (const std::string index = IndexUsed(c, r); !index.empty())
    out << ", index " << index
        << (Lower(c.scale.approximate.engine) == kAutoApproximateEngine
                ? " (Approximate_engine auto)"
                : "");
  out << "\n";
  const Cluster& cluster = Cluster::Get();
  if (cluster.Distributed())
    out << "  processes: " << cluster.Size() << " (mpirun; each described and matched its "
        << "share, the timings below are process 0's)\n";
  if (r.bounded) {
    out << "  bounded: " << r.matches.size() << " matches kept (Best_matches " << c.scale.keep.best
        << ", Band_width " << c.scale.keep.band << "), max distance " << r.max_distance
        << " (Eq. 5 divisor over the cells computed)";
  } else {
    out << "  matrix: " << r.normalized.rows << "x" << r.normalized.cols << ", max distance "
        << r.max_distance << " (Eq. 5 divisor)";
  }
  if (r.empty_cells > 0)
    out << ", " << r.empty_cells << " cells without a value (Sequence_partial "
        << EnumName(c.matching.partial) << ")";
  if (!r.thresholded.empty())
    out << ", threshold " << c.matching.threshold << ": "
        << r.thresholded.total() - static_cast<size_t>(cv::countNonZero(r.thresholded))
        << " cells below";
  if (r.accepted_queries >= 0) {
    out << "\n  accepted: " << r.accepted_queries << " of " << r.answered_queries
        << " best matches with " << EnumName(c.matching.score.kind)
        << " score <= " << c.matching.match_threshold << " (Match_threshold)";
    if (c.matching.match_consistency > 0)
      out << " confirmed by " << c.matching.match_consistency
          << (c.matching.match_consistency == 1 ? " independent query" : " independent queries")
          << " (Match_consistency)";
  }
  for (const std::string& w : r.warnings) out << "\n  warning: " << w;
  if (outcome.automatic) {
    const std::string lines = FormatAutoReport(*outcome.automatic);
    out << "\n" << lines.substr(0, lines.size() - 1);  // each line ends the one before
  }
  if (const RunVerification* v = outcome.verification.get()) {
    const VerificationOptions& o = v->options;
    out << "\n  verification: " << EnumName(o.features) << " (" << o.max_features
        << " features), ratio " << FormatNumber(o.ratio) << ", " << v->geometry << ", RANSAC "
        << FormatNumber(o.ransac_threshold) << " px, >= " << o.min_inliers << " inliers, "
        << o.candidates << " candidates per query, consistency " << o.consistency << " (+-"
        << o.tolerance << " frames)"
        << "\n    " << v->queries.size() << " queries, " << v->pairs << " candidates checked, "
        << v->geometric << " geometrically verified; " << v->answered
        << " queries answered by a verified loop";
    if (v->extractions > v->frames)
      out << "\n    features of " << v->frames << " frames computed " << v->extractions
          << " times (Verification_cache " << FormatNumber(o.cache_mb) << " MB is full)";
  }
  out << "\nTimings (wall clock):\n"
      << "  total            " << FormatFixed(tm.total_seconds, 3) << " s\n"
      << "  description      " << FormatFixed(tm.describe_seconds, 3) << " s  ("
      << FormatFixed(tm.frames ? 1e3 * tm.describe_seconds / tm.frames : 0, 3) << " ms per image, "
      << tm.frames << " images, reading included)\n"
      << "  matching         " << FormatFixed(tm.match_seconds, 3) << " s  ("
      << FormatFixed(tm.pairs ? 1e9 * tm.match_seconds / static_cast<double>(tm.pairs) : 0, 1)
      << " ns per pair, " << tm.pairs << " pairs)\n"
      << "  sequences+norm.  " << FormatFixed(tm.sequence_seconds, 3) << " s\n";
  if (const RunVerification* v = outcome.verification.get()) {
    const LatencySummary features = Summarize(v->extract_ms), pairs = Summarize(v->pair_ms);
    out << "  verification     " << FormatFixed(v->seconds, 3) << " s  (features "
        << FormatFixed(features.mean, 2) << " ms per frame, p99 " << FormatFixed(features.p99, 2)
        << "; check " << FormatFixed(pairs.mean, 2) << " ms per candidate, p99 "
        << FormatFixed(pairs.p99, 2) << ")\n";
  }
  if (evaluation != nullptr)
    out << "  evaluation       " << FormatFixed(tm.evaluate_seconds, 3) << " s\n";
  out << "  export           " << FormatFixed(tm.export_seconds, 3) << " s\n";
  if (evaluation != nullptr) out << FormatEvaluationTable(evaluation->settings, evaluation->runs);
  if (outcome.written.empty()) {
    out << "No output file was asked for (set Txt_name, Npy_name or Png_name).\n";
  } else {
    out << "Wrote:\n";
    for (const auto& p : outcome.written) out << "  " << p << "\n";
  }
  return ToValidUtf8(out.str());
}

std::string EncodeRunJson(const Config& config, const RunOutcome& outcome) {
  const Config& c = outcome.automatic ? outcome.automatic->config : config;
  const RunResult& r = outcome.result;
  const RunTimings& tm = r.timings;
  Json o;
  o["program"] = "Test_OpenABLE";
  o["openable_version"] = kVersion;
  Json& descriptors = o["descriptors"] = Json::array();
  for (const RunDescriptor& e : r.descriptors)
    descriptors.push_back({{"name", e.name},
                           {"row_width", e.row_width},
                           {"metric", e.metric == Metric::kL2   ? "L2"
                                      : e.metric == Metric::kL1 ? "L1"
                                                                : "Hamming"}});
  o["camera"] = r.camera;
  Json& traversals = o["traversals"] = Json::array();
  for (const Traversal& v : r.traversals)
    traversals.push_back({{"key", v.key},
                          {"path", v.path},
                          {"frames", v.frames},
                          {"first_row", v.first_row},
                          {"frame_width", v.frame_size.width},
                          {"frame_height", v.frame_size.height},
                          {"skipped", json::Strings(v.skipped)}});
  o["mode"] = r.mode_reason;
  o["bounded"] = r.bounded;
  const std::string index = IndexUsed(c, r);
  o["index"] = index.empty() ? Json() : Json(index);
  if (r.bounded)
    o["matches_kept"] = r.matches.size();
  else
    o["matrix"] = {{"rows", r.normalized.rows}, {"cols", r.normalized.cols}};
  o["max_distance"] = json::Number(r.max_distance);
  o["empty_cells"] = r.empty_cells;
  o["threshold_cells_below"] =
      r.thresholded.empty()
          ? Json()
          : Json(r.thresholded.total() - static_cast<std::size_t>(cv::countNonZero(r.thresholded)));
  o["accepted"] = Json();
  if (r.accepted_queries >= 0)
    o["accepted"] = {{"queries", r.accepted_queries},
                     {"answered", r.answered_queries},
                     {"match_threshold", json::Number(c.matching.match_threshold)},
                     {"match_consistency", c.matching.match_consistency}};
  o["verification"] = Json();
  if (const RunVerification* v = outcome.verification.get())
    o["verification"] = {{"queries", v->queries.size()},
                         {"candidates_checked", v->pairs},
                         {"geometric", v->geometric},
                         {"answered", v->answered},
                         {"seconds", json::Number(v->seconds)}};
  o["timings"] = {{"total", json::Number(tm.total_seconds)},
                  {"description", json::Number(tm.describe_seconds)},
                  {"matching", json::Number(tm.match_seconds)},
                  {"sequences", json::Number(tm.sequence_seconds)},
                  {"evaluation", json::Number(tm.evaluate_seconds)},
                  {"export", json::Number(tm.export_seconds)},
                  {"frames", tm.frames},
                  {"pairs", tm.pairs}};
  const Evaluation* e = outcome.evaluation.get();
  o["evaluation"] = e != nullptr ? EvaluationJson(e->settings, e->runs, kVersion) : Json();
  o["auto"] = outcome.automatic ? AutoJson(*outcome.automatic) : Json();
  o["notes"] = json::Strings(r.notes);
  o["written"] = json::Strings(outcome.written);
  return json::Dump(o);
}

std::string ProgramJson(const std::string& program,
                        const std::vector<std::pair<std::string, Json>>& members,
                        const std::vector<std::string>& written) {
  Json o;
  o["program"] = program;
  o["openable_version"] = kVersion;
  for (const auto& [name, value] : members) o[name] = value;
  o["written"] = json::Strings(written);
  return json::Dump(o);
}

}  // namespace openable
