#include "matching/search/engine_registry.h"

#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "matching/search/approximate_engine.h"
#include "matching/search/binary_ivf.h"
#include "matching/search/faiss_engines.h"
#include "matching/search/flann_engine.h"

namespace openable {
namespace {

// The one table of engines, in the order shown to users (auto comes after them).
const ApproximateEngineEntry* const kEngines[] = {
    &kFlannEngine,      // matching/search/flann_engine.h
    &kHnswEngine,       // matching/search/faiss_engines.h
    &kIvfEngine,        // matching/search/faiss_engines.h
    &kBinaryIvfEngine,  // matching/search/binary_ivf.h
};

// What auto stands for, measured by bench/bench_approximate (docs/matching.md, "Choosing an
// engine"): the faster engine at a given recall on each kind of rows.
const ApproximateEngineEntry& AutoEngine(int depth) {
  return depth == CV_8U ? kIvfEngine : kHnswEngine;
}
const char* const kAutoReason = "the faster at a given recall for each in docs/benchmarks.md";

// The entry named `name` (any case), or nullptr (also for auto).
const ApproximateEngineEntry* Find(std::string_view name) {
  const std::string lower = Lower(name);
  for (const ApproximateEngineEntry* e : kEngines)
    if (lower == e->name) return e;
  return nullptr;
}

bool IsAuto(std::string_view name) { return Lower(name) == kAutoApproximateEngine; }

// "a, b or c" (`last` between the last two) of `names`.
std::string Listed(const std::vector<std::string>& names, const char* last) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? last : ", ";
    out += names[i];
  }
  return out;
}

bool EntryAvailable(const ApproximateEngineEntry& e) { return !e.needs_faiss || FaissAvailable(); }

}  // namespace

std::vector<std::string> ApproximateEngineNames() {
  std::vector<std::string> names;
  for (const ApproximateEngineEntry* e : kEngines) names.emplace_back(e->name);
  names.emplace_back(kAutoApproximateEngine);
  return names;
}

std::string ApproximateEngineChoices() { return Listed(ApproximateEngineNames(), " or "); }

bool IsApproximateEngine(std::string_view name) { return IsAuto(name) || Find(name) != nullptr; }

std::string ParseApproximateEngine(std::string_view text, const std::string& key) {
  if (IsAuto(text)) return kAutoApproximateEngine;
  if (const ApproximateEngineEntry* e = Find(text)) return e->name;
  throw InputError(key + ": " + Quoted(text) + " is not valid; expected " +
                   ApproximateEngineChoices());
}

const ApproximateEngineEntry& FindApproximateEngine(std::string_view engine, int depth) {
  const std::string name = ParseApproximateEngine(engine, "ApproximateOptions::engine");
  return IsAuto(name) ? AutoEngine(depth) : *Find(name);
}

std::string ResolvedEngine(std::string_view engine, int depth) {
  return FindApproximateEngine(engine, depth).name;
}

bool FaissAvailable() {
#ifdef OPENABLE_HAVE_FAISS
  return true;
#else
  return false;
#endif
}

bool ApproximateEngineAvailable(std::string_view engine) {
  return EntryAvailable(FindApproximateEngine(engine, CV_8U)) &&
         EntryAvailable(FindApproximateEngine(engine, CV_32F));
}

void CheckEngineAvailable(std::string_view engine, const std::string& key) {
  const std::string name = ParseApproximateEngine(engine, key);
  if (ApproximateEngineAvailable(name)) return;
  std::vector<std::string> available;
  for (const ApproximateEngineEntry* e : kEngines)
    if (EntryAvailable(*e)) available.emplace_back(e->name);
  throw InputError(key + ": " + name +
                   " needs FAISS, which this build does not have (libfaiss-dev and OpenMP were "
                   "not found when it was configured); expected " +
                   Listed(available, " or "));
}

std::string ApproximateEngineHelp() {
  std::string out;
  std::vector<std::string> need_faiss;
  for (const ApproximateEngineEntry* e : kEngines) {
    out += std::string(e->name) + ", " + e->summary + "; ";
    if (e->needs_faiss) need_faiss.emplace_back(e->name);
  }
  const ApproximateEngineEntry &binary = AutoEngine(CV_8U), &vector = AutoEngine(CV_32F);
  out += std::string(kAutoApproximateEngine) + " (the default), " + binary.name +
         " for binary descriptors (LDB, ORB, ...) and " + vector.name +
         " for vector ones (SIFT, HOG), " + kAutoReason + ".";
  if (binary.needs_faiss || vector.needs_faiss) need_faiss.emplace_back(kAutoApproximateEngine);
  if (!need_faiss.empty())
    out += " " + Listed(need_faiss, " and ") + (need_faiss.size() == 1 ? " needs" : " need") +
           " a build with FAISS (libfaiss-dev).";
  return out;
}

}  // namespace openable
