// The evaluation protocols an evaluation can report (Evaluation_protocol): the toolbox's own
// (per query and ABLE-P, always computed: its files and figures need them) and the reference
// protocols of other evaluation codes, one table of them. A reference protocol is a function
// that gives its figures of a matrix, and an entry of the table; every report (the table
// printed, the JSON, the HTML report, the curve files, Python) reads the figures it gives.
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"

namespace openable {

// What one reference protocol gives for one matrix.
struct ProtocolFigures {
  std::string protocol;  // its name in the table
  // Its row of the "By protocol" table: AUC, R@100P and R@1/5/10 as the protocol defines them
  // (NaN where it leaves one undefined), then a few more figures as text.
  double auc = std::numeric_limits<double>::quiet_NaN();
  double recall_at_100p = std::numeric_limits<double>::quiet_NaN();
  double recall_at_1 = std::numeric_limits<double>::quiet_NaN();
  double recall_at_5 = std::numeric_limits<double>::quiet_NaN();
  double recall_at_10 = std::numeric_limits<double>::quiet_NaN();
  std::string more;
  nlohmann::ordered_json json;     // the run's member of this name in Evaluation_name.json
  nlohmann::ordered_json details;  // Python's property of this name: the figures and curves
  std::string csv;                 // the curve file (ReferenceProtocol::csv_suffix)
};

using ProtocolFunction = ProtocolFigures (*)(const cv::Mat1f& normalized,
                                             const EvaluationLayout& layout,
                                             const GroundTruth& truth, int tolerance);

struct ReferenceProtocol {
  const char* name;        // the value of Evaluation_protocol, lower case
  const char* help;        // what it reports, for Evaluation_protocol's help
  const char* csv_suffix;  // its curve file: <Evaluation_name>[_<run>]<csv_suffix>
  ProtocolFunction evaluate;
};

// The reference protocols, in the order of every report.
const std::vector<ReferenceProtocol>& ReferenceProtocols();
// The entry of `name`; nullptr when there is none.
const ReferenceProtocol* FindReferenceProtocol(const std::string& name);

// The protocols reported (Evaluation_protocol).
struct EvaluationProtocols {
  bool openable = true;
  std::vector<std::string> reference;  // names of ReferenceProtocols(), in the table's order

  bool Has(const std::string& name) const;
  bool operator==(const EvaluationProtocols& o) const {
    return openable == o.openable && reference == o.reference;
  }
};

// "openable", a reference protocol's name, several joined by commas, or "all"
// (case-insensitive). Throws InputError naming Evaluation_protocol otherwise.
EvaluationProtocols ParseEvaluationProtocols(const std::string& text);
// The canonical text: "openable", "openable,vpr_bench", ...
std::string EvaluationProtocolsText(const EvaluationProtocols& protocols);
// Each name with what it reports, for Evaluation_protocol's help.
std::string EvaluationProtocolsHelp();
// "openable, vpr_bench, vpr_tutorial".
std::string EvaluationProtocolNames();

// A figure of the tables: %.3f, "-" when it is not defined (NaN).
std::string FigureText(double value);

// The figures of each reference protocol of `protocols` on the block of `layout` of
// `normalized`, in the table's order. Throws InputError as the protocols do (a protocol that
// needs two traversals, given one sequence).
std::vector<ProtocolFigures> EvaluateReferenceProtocols(const cv::Mat1f& normalized,
                                                        const EvaluationLayout& layout,
                                                        const GroundTruth& truth,
                                                        const EvaluationProtocols& protocols,
                                                        int tolerance);

}  // namespace openable
