#include "OpenABLE/evaluation/report.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

std::string Number(double v) {
  return std::isfinite(v) ? FormatNumber(v, 9) : "null";  // JSON has no NaN or infinity
}

// JSON string literal (OpenCV's FileStorage writes JSON too, but not null for non-finite
// values, so the few objects here are written directly).
std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
      out += buffer;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

const char* KindName(EvaluationLayout::Kind kind) {
  return kind == EvaluationLayout::Kind::kLoopClosure ? "loop_closure" : "query_reference";
}

}  // namespace

std::string EncodeCurveCsv(const std::vector<CurvePoint>& curve) {
  std::string out = "threshold,precision,recall,f1,tp,fp\n";
  for (const CurvePoint& p : curve) {
    out += Number(p.threshold) + "," + Number(p.precision) + "," + Number(p.recall) + "," +
           Number(p.f1) + "," + std::to_string(p.tp) + "," + std::to_string(p.fp) + "\n";
  }
  return out;
}

std::string JsonNumber(double v) { return Number(v); }

std::string JsonText(const std::string& s) { return JsonString(s); }

std::string EncodeEvaluationSettingsJson(const EvaluationSettings& s, const std::string& indent) {
  std::ostringstream o;
  const GroundTruthOptions& t = s.truth;
  const std::string in = indent + "  ";
  o << "{\n"
    << in << "\"ground_truth_type\": " << JsonString(GroundTruthTypeName(t.type)) << ",\n"
    << in << "\"ground_truth\": " << JsonString(t.path) << ",\n"
    << in << "\"ground_truth_2\": " << JsonString(t.path_2) << ",\n"
    << in << "\"ground_truth_base\": " << t.base << ",\n"
    << in << "\"first_frame\": " << t.first_frame << ",\n"
    << in << "\"radius\": " << Number(t.radius) << ",\n"
    << in << "\"heading_limit_deg\": " << Number(t.heading_limit) << ",\n"
    << in << "\"min_frame_gap\": " << t.min_frame_gap << ",\n"
    << in << "\"axes\": " << JsonString(t.axes) << ",\n"
    << in << "\"tolerance\": " << s.options.tolerance << ",\n"
    << in << "\"exclusion\": " << s.options.exclusion << ",\n"
    << in << "\"vicinity\": " << s.options.vicinity << ",\n"
    << in << "\"match_score\": " << JsonString(EnumName(s.options.score)) << ",\n"
    << in << "\"match_score_window\": " << s.options.score_window << ",\n"
    << in << "\"match_threshold\": " << Number(s.options.accept_threshold) << ",\n"
    << in << "\"match_consistency\": " << s.options.accept_consistency << ",\n"
    << in << "\"accept_none\": " << (s.options.accept_none ? "true" : "false") << ",\n"
    << in << "\"able_thresholds\": " << s.options.able_thresholds << "\n"
    << indent << "}";
  return o.str();
}

namespace {

// The members of a "per_query" object, each line indented by `in`.
std::string PerQueryJson(const PerQueryResult& q, const std::string& in) {
  std::ostringstream o;
  o << in << "  \"auc\": " << Number(q.auc) << ",\n"
    << in << "  \"recall_at_100p\": " << Number(q.recall_at_100p) << ",\n"
    << in << "  \"max_f1\": " << Number(q.max_f1) << ",\n"
    << in << "  \"max_f1_threshold\": " << Number(q.max_f1_threshold) << ",\n"
    << in << "  \"max_f1_precision\": " << Number(q.max_f1_precision) << ",\n"
    << in << "  \"max_f1_recall\": " << Number(q.max_f1_recall) << ",\n"
    << in << "  \"recall_at_1\": " << Number(q.recall_at_1) << ",\n"
    << in << "  \"recall_at_5\": " << Number(q.recall_at_5) << ",\n"
    << in << "  \"recall_at_10\": " << Number(q.recall_at_10) << ",\n"
    << in << "  \"queries\": " << q.queries << ",\n"
    << in << "  \"positive_queries\": " << q.positive_queries << ",\n"
    << in << "  \"unanswered_queries\": " << q.unanswered << ",\n"
    << (q.has_operating_point
            ? in + "  \"accepted\": {\"threshold\": " + Number(q.operating_point.threshold) +
                  ", \"matches\": " +
                  std::to_string(q.operating_point.tp + q.operating_point.fp) +
                  ", \"precision\": " + Number(q.operating_point.precision) +
                  ", \"recall\": " + Number(q.operating_point.recall) + "},\n"
            : std::string())
    << in << "  \"truth_pairs_outside_candidates\": " << q.truth_pairs_outside_candidates
    << "\n";
  return o.str();
}

}  // namespace

std::string EncodeEvaluatedRunFieldsJson(const EvaluatedRun& r, const std::string& indent) {
  const std::string& in = indent;
  std::ostringstream o;
  o << in << "\"label\": " << JsonString(r.label) << ",\n"
    << in << "\"source\": " << JsonString(r.source) << ",\n"
    << in << "\"layout\": {\"kind\": " << JsonString(KindName(r.layout.kind))
    << ", \"queries\": " << r.layout.queries << ", \"references\": " << r.layout.references
    << ", \"row_offset\": " << r.layout.row_offset << ", \"col_offset\": " << r.layout.col_offset
    << "},\n"
    << in << "\"ground_truth\": {\"pairs\": " << r.truth_pairs << ", \"dropped\": "
    << r.truth_dropped << "},\n"
    << in << "\"verified\": " << (r.verified ? "true" : "false") << ",\n"
    << in << "\"per_query\": {\n" << PerQueryJson(r.per_query, in) << in << "},\n";
  if (r.verified)
    o << in << "\"per_query_unverified\": {\n" << PerQueryJson(r.per_query_unverified, in)
      << in << "},\n";
  o << in << "\"able_p\": {\n"
    << in << "  \"average_precision_percent\": " << Number(r.able_p.average_precision) << ",\n"
    << in << "  \"candidate_cells\": " << r.able_p.candidate_cells << ",\n"
    << in << "  \"truth_cells\": " << r.able_p.truth_cells << "\n"
    << in << "}";
  return o.str();
}

std::string EncodeEvaluationJson(const EvaluationSettings& s, const std::vector<EvaluatedRun>& runs,
                                 const std::string& version) {
  std::ostringstream o;
  o << "{\n  \"openable_version\": " << JsonString(version) << ",\n";
  o << "  \"settings\": " << EncodeEvaluationSettingsJson(s, "  ") << ",\n";
  o << "  \"runs\": [";
  for (std::size_t i = 0; i < runs.size(); ++i)
    o << (i ? ",\n" : "\n") << "    {\n" << EncodeEvaluatedRunFieldsJson(runs[i], "      ")
      << "\n    }";
  o << "\n  ]\n}\n";
  return o.str();
}

std::string FormatEvaluationTable(const EvaluationSettings& s,
                                  const std::vector<EvaluatedRun>& runs) {
  std::ostringstream o;
  o << "Evaluation against " << GroundTruthTypeName(s.truth.type) << " ground truth"
    << (s.truth.path.empty() ? "" : " \"" + s.truth.path + "\"") << ": tolerance +-"
    << s.options.tolerance << " frames";
  if (!runs.empty() && runs[0].layout.kind == EvaluationLayout::Kind::kLoopClosure)
    o << ", candidates at least " << s.options.exclusion << " frames back";
  if (s.options.score == MatchScore::kRatio)
    o << "; score: ratio to the best rival beyond +-" << s.options.score_window << " frames";
  o << "; ABLE-P vicinity " << s.options.vicinity << "\n";
  char line[512];
  std::snprintf(line, sizeof line, "  %-18s %7s %7s %7s %7s %16s %6s %6s %6s %8s\n", "run",
                "queries", "pos.", "AUC", "R@100P", "max F1 (thr.)", "R@1", "R@5", "R@10",
                "ABLE AP");
  o << line;
  for (const EvaluatedRun& r : runs) {
    // With verification: the matrix's answers first, then the verified ones.
    const bool both = r.verified;
    for (int pass = both ? 0 : 1; pass < 2; ++pass) {
      const PerQueryResult& q = pass == 0 ? r.per_query_unverified : r.per_query;
      const std::string label = pass == 0 || !both ? r.label.substr(0, 18)
                                                   : std::string("  + verification");
      char f1[32];
      std::snprintf(f1, sizeof f1, "%.3f (%.3f)", q.max_f1, q.max_f1_threshold);
      std::snprintf(line, sizeof line,
                    "  %-18s %7d %7d %7.3f %7.3f %16s %6.3f %6.3f %6.3f %7.1f%%\n",
                    label.c_str(), q.queries, q.positive_queries, q.auc, q.recall_at_100p, f1,
                    q.recall_at_1, q.recall_at_5, q.recall_at_10, r.able_p.average_precision);
      o << line;
      if (pass == 0 || !both) {
        if (q.truth_pairs_outside_candidates > 0)
          o << "    (" << q.truth_pairs_outside_candidates
            << " ground-truth pairs are not candidates: inside the exclusion window)\n";
        if (r.truth_dropped > 0)
          o << "    (" << r.truth_dropped
            << " ground-truth pairs dropped: on the diagonal or outside the processed "
               "frames)\n";
      }
      if (q.unanswered > 0)
        o << "    (" << q.unanswered
          << (pass == 1 && both
                  ? " queries have no verified candidate: no answer, counted as misses)\n"
                  : " queries have no candidate with a full sequence: no answer, counted as "
                    "misses)\n");
      if (q.has_operating_point) {
        const CurvePoint& p = q.operating_point;
        std::string at = std::isfinite(p.threshold)
                             ? "accepted at score <= " + FormatNumber(p.threshold)
                             : std::string("accepted (every verified answer)");
        if (s.options.accept_consistency > 0)
          at += std::string(" and confirmed by ") +
                (s.options.accept_consistency == 1
                     ? "a partner"
                     : std::to_string(s.options.accept_consistency) + " partners") +
                " (Match_consistency)";
        if (s.options.accept_none) {
          o << "    accepted: none (the auto mode found no setting consistent enough to trust, "
               "Auto_min_consistency)\n";
        } else {
          std::snprintf(line, sizeof line, "    %s: %lld answers, precision %.3f, recall %.3f\n",
                        at.c_str(), static_cast<long long>(p.tp + p.fp), p.precision, p.recall);
          o << line;
        }
      }
    }
  }
  return o.str();
}

}  // namespace openable
