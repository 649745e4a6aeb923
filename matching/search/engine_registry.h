// The engines of approximate search (ApproximateIndex, matching/search/approximate.h) by name:
// the values of ApproximateOptions::engine, of the key Approximate_engine, of the online
// detector and of bench_online's --engine, plus "auto" (the default: the engine for the rows'
// kind, ResolvedEngine). Every list users see (help, Markdown reference, errors, Python
// docstrings) is made from the one table in engine_registry.cc, as descriptors' names come from
// descriptors/registry.cc. Adding an engine: docs/matching.md, "Adding an engine".
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace openable {

struct ApproximateEngineEntry;  // matching/search/approximate_engine.h

// The name that stands for the engine chosen by the rows' kind; the default engine.
inline constexpr char kAutoApproximateEngine[] = "auto";

// The names ApproximateOptions::engine accepts, in the order shown to users: every engine of
// the table, then "auto".
std::vector<std::string> ApproximateEngineNames();

// Those names as a message lists them: "a, b, c or auto".
std::string ApproximateEngineChoices();

// The canonical (table) spelling of `text`, compared case-insensitively. Throws InputError
// "<key>: "<text>" is not valid; expected a, b, c or auto" when it names no engine.
std::string ParseApproximateEngine(std::string_view text, const std::string& key);

// Whether `name` (any case) is one of ApproximateEngineNames().
bool IsApproximateEngine(std::string_view name);

// The engine `engine` stands for on rows of OpenCV depth `depth` (CV_8U: binary rows compared
// by Hamming distance; otherwise float rows, L2): auto becomes the engine the table chooses
// for that kind, the others are themselves; always the canonical name. Throws InputError
// naming ApproximateOptions::engine when `engine` is no engine.
std::string ResolvedEngine(std::string_view engine, int depth);

// Whether this build has FAISS: false when libfaiss-dev or OpenMP was not found when the
// build was configured.
bool FaissAvailable();

// Whether `engine` (auto: every engine it may stand for) can run in this build: false for an
// engine that needs FAISS in a build without it. Throws as ParseApproximateEngine with the key
// "ApproximateOptions::engine" when `engine` names none.
bool ApproximateEngineAvailable(std::string_view engine);

// Throws InputError "<key>: <engine> needs FAISS, which this build does not have (...);
// expected <the engines that do not>" when ApproximateEngineAvailable(engine) is false, and
// the error of ParseApproximateEngine when `engine` names none.
void CheckEngineAvailable(std::string_view engine, const std::string& key);

// What each name means, for the help of the key Approximate_engine and the Python docstring:
// "a, <what a is>; b, ...; auto (the default), <its choice for binary and for float rows>.
// <the engines that need FAISS> need a build with FAISS (libfaiss-dev)."
std::string ApproximateEngineHelp();

// The table's entry of `engine` (auto resolved for `depth` first). Throws as ResolvedEngine.
const ApproximateEngineEntry& FindApproximateEngine(std::string_view engine, int depth);

}  // namespace openable
