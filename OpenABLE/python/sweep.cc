// openable.sweep: the sweep of openable_sweep (OpenABLE/tuning/sweep.h) from Python.
#include "OpenABLE/tuning/sweep.h"

#include <pybind11/stl.h>

#include <iostream>
#include <memory>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/python/common.h"

namespace openable::python {
namespace {

// A value of a settings or vary dict as Config.txt text (True and False as 1 and 0).
std::string ValueText(const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "1" : "0";
  return py::str(v).cast<std::string>();
}

struct Sweep {
  SweepResult result;
  std::vector<std::string> written;
};

py::dict RunDict(const SweepResult& r, std::size_t i) {
  const SweepRun& run = r.runs[i];
  const PerQueryResult& q = run.evaluation.per_query;
  py::dict settings;
  for (std::size_t a = 0; a < r.axes.size(); ++a) settings[r.axes[a].key.c_str()] = run.values[a];
  py::dict d;
  d["rank"] = i + 1;
  d["settings"] = settings;
  d["label"] = run.label;
  d["consistency"] = run.unsupervised.consistency;
  d["distinctiveness"] = run.unsupervised.distinctiveness;
  d["agreement"] = run.unsupervised.agreement;
  // The figures of the evaluation: None without ground truth.
  const auto figure = [&](double v) -> py::object {
    return r.evaluated ? py::cast(v) : py::none();
  };
  d["auc"] = figure(q.auc);
  d["recall_at_100p"] = figure(q.recall_at_100p);
  d["max_f1"] = figure(q.max_f1);
  d["max_f1_threshold"] = figure(q.max_f1_threshold);
  d["recall_at_1"] = figure(q.recall_at_1);
  d["recall_at_5"] = figure(q.recall_at_5);
  d["recall_at_10"] = figure(q.recall_at_10);
  d["average_precision"] = figure(run.evaluation.able_p.average_precision);
  d["queries"] = r.evaluated ? q.queries : run.unsupervised.queries;
  d["unanswered_queries"] =
      r.evaluated ? q.unanswered : run.unsupervised.queries - run.unsupervised.answered;
  d["seconds"] = run.seconds;
  d["described"] = run.described;
  return d;
}

}  // namespace

void RegisterSweep(py::module_& m) {
  py::class_<Sweep>(m, "SweepResult", R"doc(What sweep() did: the runs ranked best first, and the
files written.

Attributes:
    runs (list[dict]): one dict per combination, best first: rank, settings ({key: value} of
        the varied keys), label, the criteria without ground truth consistency,
        distinctiveness and agreement (docs/evaluation.md), then the figures of the
        evaluation, None without ground truth: auc, recall_at_100p, max_f1, max_f1_threshold,
        recall_at_1, recall_at_5, recall_at_10, average_precision (ABLE-P, percent); queries,
        unanswered_queries, seconds, described (False: the run took the single-frame matrices
        of an earlier run).
    rank_by (str): the figure runs are ranked by.
    descriptions (int): single-frame matrices computed (frames described that many times).
    frame_reads (int): times the frames were read and decoded (once per description setting,
        for all its descriptors).
    seconds (float): wall time of the sweep.
    written (list[str]): paths written (output given).

Methods: table() (the ranked table openable_sweep prints), to_csv(), to_json().)doc")
      .def_property_readonly(
          "runs",
          [](const Sweep& s) {
            py::list runs;
            for (std::size_t i = 0; i < s.result.runs.size(); ++i)
              runs.append(RunDict(s.result, i));
            return runs;
          },
          "list[dict]: one dict per combination, best first (see the class).")
      .def_property_readonly(
          "rank_by", [](const Sweep& s) { return EnumName(s.result.rank_by); },
          "str: the figure the runs are ranked by.")
      .def_property_readonly(
          "descriptions", [](const Sweep& s) { return s.result.descriptions; },
          "int: single-frame matrices computed (frames described that many times).")
      .def_property_readonly(
          "frame_reads", [](const Sweep& s) { return s.result.frame_reads; },
          "int: times the frames were read and decoded (once per description setting).")
      .def_property_readonly(
          "seconds", [](const Sweep& s) { return s.result.seconds; },
          "float: wall time of the sweep.")
      .def_property_readonly(
          "written", [](const Sweep& s) { return s.written; },
          "list[str]: the paths written (output given), else empty.")
      .def(
          "table", [](const Sweep& s) { return FormatSweepTable(s.result); },
          "table() -> str\n\nThe ranked table, as openable_sweep prints it.")
      .def(
          "to_csv", [](const Sweep& s) { return EncodeSweepCsv(s.result); },
          "to_csv() -> str\n\nThe ranked rows as CSV (the file openable_sweep writes).")
      .def(
          "to_json", [](const Sweep& s) { return EncodeSweepJson(s.result, kVersion); },
          "to_json() -> str\n\nThe whole sweep as JSON (the file openable_sweep writes).")
      .def("__repr__", [](const Sweep& s) {
        return "<openable.SweepResult " + std::to_string(s.result.runs.size()) +
               " runs ranked by " + EnumName(s.result.rank_by) + ">";
      });

  m.def(
      "sweep",
      [](const py::object& config, const py::dict& vary, const py::object& settings,
         const std::string& rank_by, int best, const py::object& output, bool quiet) {
        Config base = config.is_none() ? Config() : LoadConfig(py::str(config).cast<std::string>());
        if (!settings.is_none())
          for (const auto item : settings.cast<py::dict>())
            ApplyOverride(base, item.first.cast<std::string>() + "=" + ValueText(item.second));
        SweepOptions options;
        for (const auto item : vary) {
          std::vector<std::string> values;
          if (py::isinstance<py::str>(item.second)) {
            values.push_back(item.second.cast<std::string>());
          } else {
            for (const py::handle v : item.second.cast<py::iterable>())
              values.push_back(ValueText(v));
          }
          // One value holding a comma (Fusion_weights "1,1") makes ';' the separator.
          bool commas = false;
          for (const std::string& v : values) commas |= v.find(',') != std::string::npos;
          std::string text = item.first.cast<std::string>() + "=";
          for (std::size_t i = 0; i < values.size(); ++i) {
            if (commas && values[i].find(';') != std::string::npos)
              throw InputError("vary: " + item.first.cast<std::string>() + ": value " +
                               Quoted(values[i]) + " holds both ',' and ';'; expected one value");
            text += (i ? (commas ? ";" : ",") : "") + values[i];
          }
          // A single string is the list itself, as on the command line ("LDB,HOG").
          if (py::isinstance<py::str>(item.second))
            text = item.first.cast<std::string>() + "=" + values.front();
          options.axes.push_back(ParseSweepAxis(text));
        }
        options.rank_by = ParseEnum<SweepRank>(rank_by, "rank_by");
        options.best = best;
        const std::string prefix = output.is_none() ? "" : py::str(output).cast<std::string>();
        auto sweep = std::make_unique<Sweep>();
        {
          py::gil_scoped_release release;
          ProgressReporter progress(std::cerr, !quiet, IsTerminal(2));
          sweep->result = RunSweep(base, options, progress, [quiet](const std::string& line) {
            if (!quiet) std::cerr << "openable.sweep: " << line << "\n";
          });
          if (!prefix.empty()) sweep->written = WriteSweep(prefix, sweep->result);
        }
        return sweep;
      },
      py::arg("config") = py::none(), py::kw_only(), py::arg("vary"),
      py::arg("settings") = py::none(), py::arg("rank_by") = "auc", py::arg("best") = 5,
      py::arg("output") = py::none(), py::arg("quiet") = true,
      R"doc(sweep(config=None, *, vary, settings=None, rank_by="auc", best=5, output=None, quiet=True) -> SweepResult

Every combination of the values in `vary`, each run as Test_OpenABLE runs the configuration
with those values set, evaluated against its ground truth and ranked: openable_sweep's library
call. Frames are described once per description setting (sequence lengths, scores, contrast
and fusion weights reuse the single-frame matrices). Every combination is checked before the
first frame is read.

Args:
    config (str | os.PathLike | None): a Config.txt with Ground_truth_type set (or set it in
        `settings`); None: the defaults.
    vary (dict): {key: [values]} (or {key: "v1,v2"} as --vary takes it), e.g.
        {"Image_descriptor": ["LDB", "HOG", "HOG+LDB"], "Image_sequences": [1, 10, 30]}.
    settings (dict | None): keys set over the configuration for every run, as --set does.
    rank_by (str): auc, recall_at_100p, recall_at_1, max_f1 or average_precision (ground
        truth needed), or agreement, consistency or distinctiveness (computed from each run's
        matrix alone; the configuration needs no Ground_truth_type).
    best (int): runs drawn in the precision-recall figure.
    output (str | None): also write <output>.csv, <output>.json and <output>_pr.png.
    quiet (bool): no progress lines on stderr.

Returns:
    SweepResult: runs (best first), descriptions, seconds, written, table(), to_csv(),
    to_json().

Raises:
    openable.InputError: one line naming the key and value (as openable_sweep).)doc");
}

}  // namespace openable::python
