// Exact against approximate k-nearest search on real data: queries per second, speed-up and
// recall of each approximate engine (matching/search/approximate.h: FLANN, FAISS HNSW, FAISS IVF),
// k = 10, all cores for every search.
//
// Data (../shared/datasets, skipped with a message when absent):
//  - "nordland": references = Nordland trimmed summer, queries = winter (1788 + 1788 frames,
//    frame-aligned: the same file name is the same place);
//  - "nordland10k", "nordland100k" and "nordland1m": the same queries against 10,000, 100,000
//    and 1,000,000 references:
//    the 1788 summer frames plus distractors, each a perturbed copy (random crop of 80-100 % of
//    the frame, gain 0.8-1.2, offset +-20 grey levels, Gaussian noise of deviation 3) of a
//    summer frame or of a KITTI 00 frame (kitti00_first1700, 1700 frames), alternately, from
//    fixed seeds. Summer copies keep their place (a copy of frame i is place i); KITTI copies
//    are no place. The 1m set has LDB only: its HOG rows would take 7.1 GB, held three times
//    (the set, the index's copy for exact distances, FAISS's own copy) on a 23 GB machine.
// Frames are read grey and resized to the 64 x 64 patch as the pipeline does (INTER_AREA when
// shrinking both sides, INTER_LINEAR otherwise: Nordland's 64 x 32 frames are stretched), then
// described with LDB (256 bits, Hamming; LSH or binary FAISS indexes) and HOG (1764 floats, L2;
// k-d trees or float FAISS indexes). An index is built once per set, descriptor and build
// setting; the settings that differ only by their search budget (checks, ef_search, nprobe)
// search the same index (ApproximateIndex::SetSearchBudget). FAISS settings are skipped with a
// message in a build without FAISS.
//
// Counters: items_per_second = queries per second; speedup = exact time / approximate time for
// the same queries; top1 and at_k as SearchRecall; place_top1 (approximate) and
// exact_place_top1: share of queries whose first candidate is within +-2 frames of the true
// place, the figure place recognition cares about; build_s = time to build the index (not in
// the search time). A summary table is printed at the end. Nothing here asserts on time.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "descriptors/registry.h"
#include "matching/search/approximate.h"

namespace {

namespace fs = std::filesystem;
using openable::ApproximateIndex;
using openable::ApproximateOptions;
using openable::CandidateLists;
using Clock = std::chrono::steady_clock;

constexpr int kK = 10;
constexpr int kPatch = 64;
constexpr int kPlaceTolerance = 2;  // frames, the usual Nordland tolerance

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

fs::path Datasets() { return fs::path(OPENABLE_DATASETS_DIR); }

std::vector<fs::path> PngFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".png") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<cv::Mat1b> ReadGray(const std::vector<fs::path>& files) {
  std::vector<cv::Mat1b> frames(files.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(files.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      frames[static_cast<size_t>(i)] =
          cv::imread(files[static_cast<size_t>(i)].string(), cv::IMREAD_GRAYSCALE);
  });
  for (size_t i = 0; i < frames.size(); ++i)
    if (frames[i].empty()) throw std::runtime_error("cannot read " + files[i].string());
  return frames;
}

// The pipeline's resize to the patch (OpenABLE/describe/describe.cc).
cv::Mat1b ToPatch(const cv::Mat1b& gray) {
  const bool shrink = gray.cols >= kPatch && gray.rows >= kPatch;
  cv::Mat1b patch;
  cv::resize(gray, patch, cv::Size(kPatch, kPatch), 0, 0,
             shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  return patch;
}

// Distractor `i`: a perturbed copy of `frame`, drawn from a generator seeded with i.
cv::Mat1b Perturbed(const cv::Mat1b& frame, int i) {
  std::mt19937 rng(0x5EED0000u + static_cast<unsigned>(i));
  std::uniform_real_distribution<double> scale(0.8, 1.0), gain(0.8, 1.2), offset(-20.0, 20.0);
  const double s = scale(rng);
  const int w = std::max(8, static_cast<int>(s * frame.cols + 0.5));
  const int h = std::max(8, static_cast<int>(s * frame.rows + 0.5));
  const int x = std::uniform_int_distribution<int>(0, frame.cols - w)(rng);
  const int y = std::uniform_int_distribution<int>(0, frame.rows - h)(rng);
  const cv::Mat1b patch = ToPatch(frame(cv::Rect(x, y, w, h)));
  cv::Mat1f f;
  patch.convertTo(f, CV_32F, gain(rng), offset(rng));
  cv::Mat1f noise(f.size());
  cv::RNG(rng()).fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  cv::Mat1b out;
  cv::Mat1f(f + noise).convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

// A benchmark data set: references and queries as rows of LDB (256 bits) and HOG (1764 floats;
// absent from the largest set, 3.5 GB), and the place of each reference (summer frame number,
// or -1 for a KITTI distractor). Query q is winter frame q, whose place is q.
struct DataSet {
  std::string error;  // set when the data is absent: the benchmarks skip with it
  cv::Mat references_ldb, references_hog, queries_ldb, queries_hog;
  std::vector<int> place;
};

// The sets: Nordland alone, and with distractors up to 50,000 and 500,000 references.
struct SetSpec {
  const char* name;
  int references;  // 0: the summer frames only
  bool hog;
};
constexpr SetSpec kSets[] = {{"nordland", 0, true},
                             {"nordland10k", 10000, true},
                             {"nordland100k", 100000, true},
                             {"nordland1m", 1000000, false}};

// Describes patch(i) for i in [0, n) into rows of LDB and (when `hog`) HOG, in parallel.
template <typename PatchOf>
void Describe(int n, bool hog, PatchOf patch_of, cv::Mat& ldb_rows, cv::Mat& hog_rows) {
  openable::DescriptorOptions options;
  options.patch_size = kPatch;
  options.ldb_bits = 256;
  const auto ldb = openable::CreateDescriptor("LDB", options);
  const auto hog_descriptor = openable::CreateDescriptor("HOG", options);
  ldb_rows.create(n, ldb->Width(), openable::RowType(*ldb));
  if (hog) hog_rows.create(n, hog_descriptor->Width(), openable::RowType(*hog_descriptor));
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const cv::Mat1b patch = patch_of(i);
      ldb->Describe(patch, ldb_rows.row(i));
      if (hog) hog_descriptor->Describe(patch, hog_rows.row(i));
    }
  });
}

DataSet Load(const SetSpec& spec) {
  DataSet set;
  const fs::path summer = Datasets() / "nordland_trimmed" / "summer";
  const fs::path winter = Datasets() / "nordland_trimmed" / "winter";
  const fs::path kitti = Datasets() / "kitti00_first1700" / "image_0";
  std::vector<fs::path> needed{summer, winter};
  if (spec.references > 0) needed.push_back(kitti);
  for (const fs::path& dir : needed)
    if (!fs::is_directory(dir)) {
      set.error = "dataset absent: " + dir.string();
      return set;
    }
  const Clock::time_point start = Clock::now();
  const std::vector<fs::path> summer_files = PngFiles(summer), winter_files = PngFiles(winter);
  if (summer_files.size() != winter_files.size() || summer_files.empty()) {
    set.error = "Nordland summer and winter hold different frame counts";
    return set;
  }
  for (size_t i = 0; i < summer_files.size(); ++i)
    if (summer_files[i].filename() != winter_files[i].filename()) {
      set.error = "Nordland frame names differ: " + summer_files[i].filename().string();
      return set;
    }
  const std::vector<cv::Mat1b> summer_frames = ReadGray(summer_files);
  const std::vector<cv::Mat1b> kitti_frames =
      spec.references > 0 ? ReadGray(PngFiles(kitti)) : std::vector<cv::Mat1b>();
  const int places = static_cast<int>(summer_frames.size());
  const int n = std::max(places, spec.references);
  const int kitti_count = static_cast<int>(kitti_frames.size());
  // Reference i < places: summer frame i. Then distractor j = i - places: a perturbed copy of
  // summer frame (j / 2) % places when j is even, of KITTI frame (j / 2) % 1700 when odd.
  auto source = [&](int i, bool& nordland) {
    const int j = i - places;
    nordland = j % 2 == 0;
    return nordland ? (j / 2) % places : (j / 2) % kitti_count;
  };
  set.place.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    bool nordland = true;
    const int s = i < places ? i : source(i, nordland);
    set.place[static_cast<size_t>(i)] = nordland ? s : -1;
  }
  Describe(
      n, spec.hog,
      [&](int i) {
        if (i < places) return ToPatch(summer_frames[static_cast<size_t>(i)]);
        bool nordland = true;
        const int s = source(i, nordland);
        return Perturbed(
            nordland ? summer_frames[static_cast<size_t>(s)] : kitti_frames[static_cast<size_t>(s)],
            i - places);
      },
      set.references_ldb, set.references_hog);
  const std::vector<cv::Mat1b> winter_frames = ReadGray(winter_files);
  Describe(
      places, spec.hog, [&](int i) { return ToPatch(winter_frames[static_cast<size_t>(i)]); },
      set.queries_ldb, set.queries_hog);
  std::printf(
      "data %s: %d references (%d Nordland summer frames, %d perturbed copies of them, "
      "%d perturbed KITTI 00 frames), %d queries (winter), LDB %d bytes%s (%.1f s to "
      "read, perturb and describe)\n",
      spec.name, n, places,
      static_cast<int>(
          std::count_if(set.place.begin() + places, set.place.end(), [](int p) { return p >= 0; })),
      static_cast<int>(std::count(set.place.begin(), set.place.end(), -1)), places,
      set.references_ldb.cols, spec.hog ? ", HOG 1764 floats" : "", Seconds(start));
  std::fflush(stdout);
  return set;
}

// Indexes built so far, by set/descriptor/build setting, with their build time.
struct BuiltIndex {
  std::unique_ptr<ApproximateIndex> index;
  double build_s = 0;
};
std::map<std::string, BuiltIndex> g_indexes;

// Sets are loaded on first use and kept; a set (and its indexes) is released once a larger one
// is needed, to bound memory (benchmarks run in registration order, smallest set first).
const DataSet& Data(int which) {
  static std::map<int, std::unique_ptr<DataSet>> sets;
  auto& slot = sets[which];
  if (!slot) {
    g_indexes.clear();
    for (auto& [other, set] : sets)
      if (other != which) set.reset();
    slot = std::make_unique<DataSet>();
    try {
      *slot = Load(kSets[which]);
    } catch (const std::exception& e) {  // an unreadable frame: skip, saying which
      slot->error = e.what();
    }
  }
  return *slot;
}

const cv::Mat& References(const DataSet& d, bool hog) {
  return hog ? d.references_hog : d.references_ldb;
}
const cv::Mat& Queries(const DataSet& d, bool hog) { return hog ? d.queries_hog : d.queries_ldb; }

std::string Key(int which, bool hog) {
  return std::string(kSets[which].name) + (hog ? "/HOG" : "/LDB");
}

// Share of queries whose first candidate is within kPlaceTolerance frames of query q's place.
double PlaceTop1(const CandidateLists& lists, const std::vector<int>& place) {
  int correct = 0;
  for (size_t q = 0; q < lists.size(); ++q) {
    if (lists[q].empty()) continue;
    const int p = place[static_cast<size_t>(lists[q][0].reference)];
    correct += p >= 0 && std::abs(p - static_cast<int>(q)) <= kPlaceTolerance;
  }
  return lists.empty() ? 0 : static_cast<double>(correct) / static_cast<double>(lists.size());
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

// Exact results and the times of exact searches (one per benchmark run), per set/descriptor.
struct Exact {
  CandidateLists lists;
  std::vector<double> seconds;
};
std::map<std::string, Exact> g_exact;

const Exact& ExactOf(int which, bool hog) {
  Exact& e = g_exact[Key(which, hog)];
  if (e.seconds.empty()) {  // BM_Exact filtered out: one timed run
    const DataSet& d = Data(which);
    const Clock::time_point start = Clock::now();
    e.lists = openable::ExactNearest(References(d, hog), Queries(d, hog), kK);
    e.seconds.push_back(Seconds(start));
  }
  return e;
}

// One line of the summary table; times are medians over the benchmark's runs (repetitions).
struct Summary {
  std::string set, descriptor, setting;
  int references = 0, queries = 0;
  std::vector<double> seconds;
  double top1 = 0, at_k = 0, exact_place = 0, place = 0, build_s = 0;
};
std::map<std::string, Summary> g_summary;  // by set/descriptor/setting

// Marks the benchmark skipped with the data set's error when it could not be read.
bool SkippedForError(benchmark::State& state, const DataSet& d) {
  if (d.error.empty()) return false;
  state.SkipWithError(d.error.c_str());
  return true;
}

void BM_Exact(benchmark::State& state, int which, bool hog) {
  const DataSet& d = Data(which);
  if (SkippedForError(state, d)) return;
  const cv::Mat& refs = References(d, hog);
  const cv::Mat& queries = Queries(d, hog);
  CandidateLists lists;
  const Clock::time_point start = Clock::now();
  for (auto _ : state) {
    lists = openable::ExactNearest(refs, queries, kK);
    benchmark::DoNotOptimize(lists.data());
  }
  Exact& e = g_exact[Key(which, hog)];
  e.seconds.push_back(Seconds(start) / static_cast<double>(state.iterations()));
  e.lists = std::move(lists);
  state.SetItemsProcessed(state.iterations() * queries.rows);
  state.counters["references"] = refs.rows;
  state.counters["place_top1"] = PlaceTop1(e.lists, d.place);
}

void BM_Approximate(benchmark::State& state, int which, bool hog, ApproximateOptions options,
                    const std::string& setting, const std::string& build_setting) {
  if (!openable::ApproximateEngineAvailable(options.engine)) {
    state.SkipWithError("this build has no FAISS (libfaiss-dev)");
    return;
  }
  const DataSet& d = Data(which);
  if (SkippedForError(state, d)) return;
  const cv::Mat& refs = References(d, hog);
  const cv::Mat& queries = Queries(d, hog);
  const Exact& exact = ExactOf(which, hog);
  options.k = kK;
  BuiltIndex& built = g_indexes[Key(which, hog) + "/" + build_setting];
  if (!built.index) {
    const Clock::time_point build_start = Clock::now();
    built.index = std::make_unique<ApproximateIndex>(refs, options);
    built.build_s = Seconds(build_start);
  }
  ApproximateIndex& index = *built.index;
  index.SetSearchBudget(options);
  const double build_s = built.build_s;
  CandidateLists lists;
  Clock::time_point start = Clock::now();
  for (auto _ : state) {
    lists = index.Search(queries);
    benchmark::DoNotOptimize(lists.data());
  }
  const double seconds = Seconds(start) / static_cast<double>(state.iterations());
  const openable::SearchRecall recall = openable::MeasureRecall(exact.lists, lists);
  const double exact_seconds = Median(exact.seconds);
  state.SetItemsProcessed(state.iterations() * queries.rows);
  state.counters["speedup"] = exact_seconds / seconds;
  state.counters["top1"] = recall.top1;
  state.counters["at_k"] = recall.at_k;
  state.counters["place_top1"] = PlaceTop1(lists, d.place);
  state.counters["exact_place_top1"] = PlaceTop1(exact.lists, d.place);
  state.counters["build_s"] = build_s;
  Summary& s = g_summary[Key(which, hog) + "/" + setting];
  s.set = kSets[which].name;
  s.descriptor = hog ? "HOG" : "LDB";
  s.setting = setting;
  s.references = refs.rows;
  s.queries = queries.rows;
  s.seconds.push_back(seconds);
  s.top1 = recall.top1;
  s.at_k = recall.at_k;
  s.exact_place = PlaceTop1(exact.lists, d.place);
  s.place = PlaceTop1(lists, d.place);
  s.build_s = build_s;
}

// Settings of each engine: LSH for LDB (checks play no part in FLANN's LSH), k-d trees for
// HOG, HNSW and IVF for both. `build` names what the index is built from (settings with the
// same `build` share one index).
struct Setting {
  std::string name, build;
  ApproximateOptions options;
};

std::vector<Setting> LshSettings() {
  std::vector<Setting> out;
  for (const auto& [tables, bits, probe] :
       std::vector<std::tuple<int, int, int>>{{12, 20, 2}, {12, 16, 2}}) {
    ApproximateOptions o;
    o.engine = "flann";
    o.lsh_tables = tables;
    o.lsh_key_bits = bits;
    o.lsh_probe_level = probe;
    const std::string name = "flann/tables:" + std::to_string(tables) +
                             "/key_bits:" + std::to_string(bits) +
                             "/probe:" + std::to_string(probe);
    out.push_back({name, name, o});
  }
  return out;
}

std::vector<Setting> KdSettings() {
  std::vector<Setting> out;
  for (const int checks : {512, 2048}) {
    ApproximateOptions o;
    o.engine = "flann";
    o.checks = checks;
    out.push_back({"flann/trees:4/checks:" + std::to_string(checks), "flann/trees:4", o});
  }
  return out;
}

std::vector<Setting> FaissSettings(const std::vector<int>& ef_searches,
                                   const std::vector<int>& nprobes) {
  std::vector<Setting> out;
  for (const int ef : ef_searches) {
    ApproximateOptions o;
    o.engine = "hnsw";
    o.ef_search = ef;
    out.push_back({"hnsw/M:32/ef_search:" + std::to_string(ef), "hnsw/M:32", o});
  }
  for (const int nprobe : nprobes) {
    ApproximateOptions o;
    o.engine = "ivf";
    o.nprobe = nprobe;
    out.push_back({"ivf/nprobe:" + std::to_string(nprobe), "ivf", o});
  }
  return out;
}

std::vector<Setting> SettingsOf(bool hog) {
  std::vector<Setting> out = hog ? KdSettings() : LshSettings();
  const std::vector<Setting> faiss =
      hog ? FaissSettings({32, 64, 128, 256}, {4, 16, 64})
          : FaissSettings({16, 32, 64, 128, 256}, {4, 16, 32, 64, 128});
  out.insert(out.end(), faiss.begin(), faiss.end());
  return out;
}

void Register() {
  for (int which = 0; which < static_cast<int>(std::size(kSets)); ++which)
    for (const bool hog : {false, true}) {
      if (hog && !kSets[which].hog) continue;
      const std::string base = Key(which, hog);
      benchmark::RegisterBenchmark(("BM_Exact/" + base).c_str(), BM_Exact, which, hog)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
      for (const Setting& s : SettingsOf(hog))
        benchmark::RegisterBenchmark(("BM_Approximate/" + base + "/" + s.name).c_str(),
                                     BM_Approximate, which, hog, s.options, s.name, s.build)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
}

void PrintSummary() {
  if (g_summary.empty()) return;
  std::printf(
      "\nk = %d, all cores for both searches, median times over the runs; speed-up = exact "
      "time / approximate time (search only, index built beforehand); place = first candidate "
      "within +-%d frames of the true place\n",
      kK, kPlaceTolerance);
  std::printf("%-12s %-4s %-34s %7s %10s %10s %8s %6s %6s %11s %11s %8s\n", "set", "desc",
              "setting", "refs", "exact q/s", "appr q/s", "speedup", "top1", "at_k", "place exact",
              "place appr", "build s");
  std::vector<const Summary*> rows;
  for (const auto& entry : g_summary) rows.push_back(&entry.second);
  std::stable_sort(rows.begin(), rows.end(), [](const Summary* a, const Summary* b) {
    return std::tie(a->references, a->descriptor) < std::tie(b->references, b->descriptor);
  });
  for (const Summary* s : rows) {
    const double exact_s = Median(g_exact[s->set + "/" + s->descriptor].seconds);
    const double approx_s = Median(s->seconds);
    std::printf("%-12s %-4s %-34s %7d %10.0f %10.0f %8.2f %6.3f %6.3f %11.3f %11.3f %8.2f\n",
                s->set.c_str(), s->descriptor.c_str(), s->setting.c_str(), s->references,
                s->queries / exact_s, s->queries / approx_s, exact_s / approx_s, s->top1, s->at_k,
                s->exact_place, s->place, s->build_s);
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!fs::is_directory(Datasets() / "nordland_trimmed"))
    std::printf("bench_approximate: dataset absent: %s (every benchmark is skipped)\n",
                (Datasets() / "nordland_trimmed").string().c_str());
  Register();
  benchmark::RunSpecifiedBenchmarks();
  PrintSummary();
  benchmark::Shutdown();
  return 0;
}
