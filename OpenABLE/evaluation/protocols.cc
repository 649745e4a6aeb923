#include "OpenABLE/evaluation/protocols.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/reference_protocols.h"

namespace openable {

const std::vector<ReferenceProtocol>& ReferenceProtocols() {
  // The one table: a new protocol is its function (its own file) and a line here.
  static const std::vector<ReferenceProtocol> kProtocols = {
      {"vpr_bench", "VPR-Bench's AUC-PR, R@100P, extended precision and RecallRate@N",
       "_vpr_bench.csv", &VprBenchFigures},
      {"vpr_tutorial", "VPR_Tutorial's multi- and single-match AUC and R@100P, R@K",
       "_vpr_tutorial.csv", &VprTutorialFigures},
  };
  return kProtocols;
}

const ReferenceProtocol* FindReferenceProtocol(const std::string& name) {
  for (const ReferenceProtocol& p : ReferenceProtocols())
    if (name == p.name) return &p;
  return nullptr;
}

std::string FigureText(double v) {
  if (!std::isfinite(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

bool EvaluationProtocols::Has(const std::string& name) const {
  for (const std::string& r : reference)
    if (r == name) return true;
  return false;
}

std::string EvaluationProtocolNames() {
  std::string out = "openable";
  for (const ReferenceProtocol& p : ReferenceProtocols()) out += std::string(", ") + p.name;
  return out;
}

EvaluationProtocols ParseEvaluationProtocols(const std::string& text) {
  const std::string all = Trim(Lower(text));
  EvaluationProtocols p{all == "all", {}};
  std::vector<bool> chosen(ReferenceProtocols().size(), all == "all");
  if (all != "all") {
    for (const std::string& name : SplitTrimmed(all, ',')) {
      if (name == "openable") {
        p.openable = true;
        continue;
      }
      const ReferenceProtocol* r = FindReferenceProtocol(name);
      if (r == nullptr)
        throw InputError("Evaluation_protocol: " + Quoted(text) + " is not valid" +
                         (name == all ? std::string() : " (" + Quoted(name) + ")") + "; expected " +
                         EvaluationProtocolNames() + ", several of them joined by commas, or all");
      chosen[static_cast<std::size_t>(r - ReferenceProtocols().data())] = true;
    }
  }
  for (std::size_t i = 0; i < chosen.size(); ++i)
    if (chosen[i]) p.reference.emplace_back(ReferenceProtocols()[i].name);
  return p;
}

std::string EvaluationProtocolsText(const EvaluationProtocols& p) {
  std::string out = p.openable ? "openable" : "";
  for (const std::string& r : p.reference) out += (out.empty() ? "" : ",") + r;
  return out;
}

std::string EvaluationProtocolsHelp() {
  std::string out = "openable (the toolbox's own: per query and ABLE-P)";
  for (const ReferenceProtocol& p : ReferenceProtocols())
    out += std::string(", ") + p.name + " (" + p.help + ")";
  return out;
}

std::vector<ProtocolFigures> EvaluateReferenceProtocols(const cv::Mat1f& normalized,
                                                        const EvaluationLayout& layout,
                                                        const GroundTruth& truth,
                                                        const EvaluationProtocols& protocols,
                                                        int tolerance) {
  std::vector<ProtocolFigures> out;
  for (const std::string& name : protocols.reference) {
    const ReferenceProtocol* p = FindReferenceProtocol(name);
    if (p == nullptr) throw std::logic_error("EvaluateReferenceProtocols: unknown " + name);
    out.push_back(p->evaluate(normalized, layout, truth, tolerance));
    out.back().protocol = p->name;
  }
  return out;
}

}  // namespace openable
