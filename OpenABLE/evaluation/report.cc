#include "OpenABLE/evaluation/report.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <utility>

#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/json.h"

namespace openable {
namespace {

const char* KindName(EvaluationLayout::Kind kind) {
  return kind == EvaluationLayout::Kind::kLoopClosure ? "loop_closure" : "query_reference";
}

// The members of a "per_query" object.
Json PerQueryJson(const PerQueryResult& q) {
  Json o;
  o["auc"] = json::Number(q.auc);
  o["recall_at_100p"] = json::Number(q.recall_at_100p);
  o["max_f1"] = json::Number(q.max_f1);
  o["max_f1_threshold"] = json::Number(q.max_f1_threshold);
  o["max_f1_precision"] = json::Number(q.max_f1_precision);
  o["max_f1_recall"] = json::Number(q.max_f1_recall);
  o["recall_at_1"] = json::Number(q.recall_at_1);
  o["recall_at_5"] = json::Number(q.recall_at_5);
  o["recall_at_10"] = json::Number(q.recall_at_10);
  o["queries"] = q.queries;
  o["positive_queries"] = q.positive_queries;
  o["unanswered_queries"] = q.unanswered;
  if (q.has_operating_point) {
    const CurvePoint& p = q.operating_point;
    o["accepted"] = {{"threshold", json::Number(p.threshold)},
                     {"matches", p.tp + p.fp},
                     {"precision", json::Number(p.precision)},
                     {"recall", json::Number(p.recall)}};
  }
  o["truth_pairs_outside_candidates"] = q.truth_pairs_outside_candidates;
  return o;
}

// The table of each run under each protocol chosen, when a reference protocol is.
void FormatProtocolTable(std::ostringstream& o, const EvaluationSettings& s,
                         const std::vector<EvaluatedRun>& runs) {
  const std::vector<ProtocolRow> rows = ProtocolRows(s, runs);
  if (rows.empty()) return;
  o << "By protocol (docs/evaluation.md; each as its code computes it, the matrix's best "
       "matches):\n";
  char line[512];
  std::snprintf(line, sizeof line, "  %-18s %-13s %7s %7s %6s %6s %6s  %s\n", "run", "protocol",
                "AUC", "R@100P", "R@1", "R@5", "R@10", "more");
  o << line;
  const std::string widened = ProtocolToleranceNote(s);
  if (!widened.empty()) o << "  (" << widened << ")\n";
  for (const ProtocolRow& r : rows) {
    std::snprintf(line, sizeof line, "  %-18s %-13s %7s %7s %6s %6s %6s  %s\n",
                  r.label.substr(0, 18).c_str(), r.protocol.c_str(), FigureText(r.auc).c_str(),
                  FigureText(r.recall_at_100p).c_str(), FigureText(r.recall_at_1).c_str(),
                  FigureText(r.recall_at_5).c_str(), FigureText(r.recall_at_10).c_str(),
                  r.more.c_str());
    o << line;
  }
}

}  // namespace

std::vector<ProtocolRow> ProtocolRows(const EvaluationSettings& s,
                                      const std::vector<EvaluatedRun>& runs) {
  std::vector<ProtocolRow> rows;
  const EvaluationProtocols& p = s.options.protocols;
  if (p.reference.empty()) return rows;
  for (const EvaluatedRun& r : runs) {
    const PerQueryResult& q = r.verified ? r.per_query_unverified : r.per_query;
    if (p.openable) {
      char more[96];
      std::snprintf(more, sizeof more, "max F1 %.3f, ABLE-P AP %.1f%%", q.max_f1,
                    r.able_p.average_precision);
      rows.push_back({r.label, "openable", q.auc, q.recall_at_100p, q.recall_at_1, q.recall_at_5,
                      q.recall_at_10, more});
    }
    for (const ProtocolFigures& f : r.reference)
      rows.push_back({r.label, f.protocol, f.auc, f.recall_at_100p, f.recall_at_1, f.recall_at_5,
                      f.recall_at_10, f.more});
  }
  return rows;
}

std::string ProtocolToleranceNote(const EvaluationSettings& s) {
  if (s.options.tolerance > 0 &&
      (s.truth.type == GroundTruthType::kVprBench || s.truth.type == GroundTruthType::kVprTutorial))
    return "Tolerance " + std::to_string(s.options.tolerance) +
           " widens the file's true references by +-" + std::to_string(s.options.tolerance) +
           " frames; Tolerance 0 takes them as the reference code does";
  return "";
}

std::string CsvNumber(double v) { return std::isfinite(v) ? FormatNumber(v, 9) : "null"; }

std::string EncodeCurveCsv(const std::vector<CurvePoint>& curve) {
  std::string out = "threshold,precision,recall,f1,tp,fp\n";
  for (const CurvePoint& p : curve) {
    out += CsvNumber(p.threshold) + "," + CsvNumber(p.precision) + "," + CsvNumber(p.recall) + "," +
           CsvNumber(p.f1) + "," + std::to_string(p.tp) + "," + std::to_string(p.fp) + "\n";
  }
  return out;
}

Json EvaluationSettingsJson(const EvaluationSettings& s) {
  const GroundTruthOptions& t = s.truth;
  Json o;
  o["ground_truth_type"] = GroundTruthTypeName(t.type);
  o["ground_truth"] = t.path;
  o["ground_truth_2"] = t.path_2;
  o["ground_truth_soft"] = t.soft_path;
  o["protocols"] = EvaluationProtocolsText(s.options.protocols);
  o["ground_truth_base"] = t.base;
  o["first_frame"] = t.first_frame;
  o["radius"] = json::Number(t.radius);
  o["heading_limit_deg"] = json::Number(t.heading_limit);
  o["min_frame_gap"] = t.min_frame_gap;
  o["axes"] = t.axes;
  o["tolerance"] = s.options.tolerance;
  o["exclusion"] = s.options.exclusion;
  o["vicinity"] = s.options.vicinity;
  o["match_score"] = EnumName(s.options.score.kind);
  o["match_score_window"] = s.options.score.window;
  o["match_threshold"] = json::Number(s.options.accept_threshold);
  o["match_consistency"] = s.options.accept_consistency;
  o["accept_none"] = s.options.accept_none;
  o["able_thresholds"] = s.options.able_thresholds;
  return o;
}

void AddEvaluatedRunJson(Json& o, const EvaluatedRun& r) {
  o["label"] = r.label;
  o["source"] = r.source;
  o["layout"] = {{"kind", KindName(r.layout.kind)},
                 {"queries", r.layout.queries},
                 {"references", r.layout.references},
                 {"row_offset", r.layout.row_offset},
                 {"col_offset", r.layout.col_offset}};
  o["ground_truth"] = {{"pairs", r.truth_pairs}, {"dropped", r.truth_dropped}};
  if (!r.truth_skipped_header.empty()) o["ground_truth"]["skipped_header"] = r.truth_skipped_header;
  o["verified"] = r.verified;
  o["per_query"] = PerQueryJson(r.per_query);
  if (r.verified) o["per_query_unverified"] = PerQueryJson(r.per_query_unverified);
  o["able_p"] = {{"average_precision_percent", json::Number(r.able_p.average_precision)},
                 {"candidate_cells", r.able_p.candidate_cells},
                 {"truth_cells", r.able_p.truth_cells}};
  for (const ProtocolFigures& f : r.reference) o[f.protocol] = f.json;
}

Json EvaluationJson(const EvaluationSettings& s, const std::vector<EvaluatedRun>& runs,
                    const std::string& version) {
  Json o;
  o["openable_version"] = version;
  o["settings"] = EvaluationSettingsJson(s);
  Json& list = o["runs"] = Json::array();
  for (const EvaluatedRun& r : runs) {
    Json run;
    AddEvaluatedRunJson(run, r);
    list.push_back(std::move(run));
  }
  return o;
}

std::string EncodeEvaluationJson(const EvaluationSettings& s, const std::vector<EvaluatedRun>& runs,
                                 const std::string& version) {
  return json::Dump(EvaluationJson(s, runs, version));
}

namespace {

// Each run's warnings, one line each, the run named when there are several.
void FormatWarnings(std::ostream& o, const std::vector<EvaluatedRun>& runs) {
  for (const EvaluatedRun& r : runs)
    for (const std::string& w : r.warnings)
      o << "  warning: " << (runs.size() > 1 ? r.label + ": " : std::string()) << w << "\n";
}

}  // namespace

std::string FormatEvaluationTable(const EvaluationSettings& s,
                                  const std::vector<EvaluatedRun>& runs) {
  std::ostringstream o;
  o << "Evaluation against " << GroundTruthTypeName(s.truth.type) << " ground truth"
    << (s.truth.path.empty() ? "" : " \"" + s.truth.path + "\"") << ": tolerance +-"
    << s.options.tolerance << " frames";
  if (!runs.empty() && runs[0].layout.kind == EvaluationLayout::Kind::kLoopClosure)
    o << ", candidates at least " << s.options.exclusion << " frames back";
  if (s.options.score.kind == MatchScore::kRatio)
    o << "; score: ratio to the best rival beyond +-" << s.options.score.window << " frames";
  o << "; ABLE-P vicinity " << s.options.vicinity << "\n";
  if (!s.options.protocols.openable) {
    FormatProtocolTable(o, s, runs);
    FormatWarnings(o, runs);
    return ToValidUtf8(o.str());
  }
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
      const std::string label =
          pass == 0 || !both ? r.label.substr(0, 18) : std::string("  + verification");
      char f1[32];
      std::snprintf(f1, sizeof f1, "%.3f (%.3f)", q.max_f1, q.max_f1_threshold);
      std::snprintf(line, sizeof line,
                    "  %-18s %7d %7d %7.3f %7.3f %16s %6.3f %6.3f %6.3f %7.1f%%\n", label.c_str(),
                    q.queries, q.positive_queries, q.auc, q.recall_at_100p, f1, q.recall_at_1,
                    q.recall_at_5, q.recall_at_10, r.able_p.average_precision);
      o << line;
      if (pass == 0 || !both) {
        if (q.truth_pairs_outside_candidates > 0)
          o << "    (" << q.truth_pairs_outside_candidates
            << " ground-truth pairs are not candidates: inside the exclusion window)\n";
        if (r.truth_dropped > 0)
          o << "    (" << r.truth_dropped
            << " ground-truth pairs dropped: on the diagonal or outside the processed "
               "frames)\n";
        if (!r.truth_skipped_header.empty())
          o << "    (ground truth " << r.truth_skipped_header << " read as a header and skipped)\n";
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
          std::snprintf(line, sizeof line,
                        "    %s: %lld answers, %lld right, precision %.3f, recall %.3f\n",
                        at.c_str(), static_cast<long long>(p.tp + p.fp),
                        static_cast<long long>(p.tp), p.precision, p.recall);
          o << line;
        }
      }
    }
  }
  FormatProtocolTable(o, s, runs);
  FormatWarnings(o, runs);
  return ToValidUtf8(o.str());
}

}  // namespace openable
