// The library's two ways in for programs that do not go through Config.txt: OnlineDetector (a
// SLAM system feeds frames one by one and gets each one's loop candidates among earlier frames)
// and batch helpers (describe images, compute the normalised matrix as Test_OpenABLE does).
//
//   #include <OpenABLE/OpenABLE.h>
//   openable::OnlineOptions options;               // LDB, global, L = 1, exclusion 100
//   options.sequence_length = 5;
//   openable::OnlineDetector detector(options);
//   for (const cv::Mat& image : camera) {
//     openable::OnlineResult r = detector.AddFrame(image);
//     for (const openable::LoopCandidate& c : r.candidates)
//       if (c.accepted) CloseLoop(r.frame, c.frame);
//   }
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "OpenABLE/describe/describe.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/verification/verification.h"
#include "descriptors/descriptor.h"
#include "matching/contrast.h"
#include "matching/distances.h"
#include "matching/score.h"
#include "matching/search/approximate.h"
#include "matching/sequence.h"

namespace openable {

struct OnlineOptions {
  // Description: the descriptor and its settings, the struct of a run's keys Image_descriptor,
  // Patch_size, Ldb_bits and Sad_patch (descriptors/descriptor.h: name "LDB", patch 64, 256
  // bits), and how a frame is cut (Description_type, Grid_x, Grid_y). A fusion of several
  // ("HOG+LDB") describes every frame with each and sums their single-frame distances, each
  // divided by its unit (see below) and weighted by fusion_weights, as a run does.
  DescriptorOptions descriptor;
  DescriptionType description = DescriptionType::kGlobal;
  int grid_x = 1, grid_y = 1;
  // Descriptors whose rows the map keeps besides those of `descriptor` ("HOG+SIFT+LDB+SAD";
  // empty: none), so that the description can later be chosen from the data among them
  // (OnlineDetector::Tune, openable_map tune): every frame is described with each. The map's
  // descriptors ("channels") are those of `descriptor`, then these.
  std::string kept_descriptors;
  // Fusion_weights: one weight per name of `descriptor`, > 0; empty: equal weights.
  std::vector<double> fusion_weights;
  // Matching.
  // L (the key Image_sequences): frames summed along the diagonal. A candidate among the first
  // L - 1 frames has fewer terms, scaled up to L (Sequence_partial scale): the frames after a
  // query, which a batch run's default (ahead) reads, are not known yet.
  int sequence_length = 1;
  // SeqSLAM's local contrast enhancement of each query's single-frame distances over
  // +-contrast_window frames of a session (matching/contrast.h; the keys Contrast_enhancement
  // and Contrast_window). It needs every distance of the query's row, so a map searched with
  // it is scanned exactly at any size (the index is not used).
  ContrastOptions contrast;
  int exclusion = 100;  // frame q's candidates are frames j <= q - exclusion (>= 1)
  int candidates = 5;   // candidates returned per frame (the k best), >= 1
  // The confidence of a candidate (matching/score.h, the key Match_score): its normalised
  // distance, or the ratio of its distance to the best candidate more than score_window
  // frames away from it (the rivals are the candidates the search scored: every searchable
  // frame while exact, the approximate candidates beyond).
  MatchScoreOptions score;
  // A candidate is accepted when its score is <= this threshold (see LoopCandidate); negative:
  // the default of the score, DefaultThreshold(score). Threshold() gives the one in use.
  double threshold = -1;
  // n (the key Match_consistency): an accepted candidate also needs the best candidates of n
  // earlier, independent queries of the same traversal to agree with it along its diagonal
  // (matching/agreement.h: each partner at least max(L, 10) frames back, sharing no frame of
  // its sequence, its best candidate the same number of frames back in the same session,
  // within the tolerance). Online there is no later query to confirm with, so the first
  // queries of a traversal (before a partner exists) are never accepted. 0: the score alone.
  // The default, 1, trades some right loops for fewer wrong ones (docs/benchmarks.md,
  // "Confirmation by earlier queries: the default").
  int consistency = 1;
  // Search: exact (every earlier frame) while the searchable map holds at most exact_limit
  // frames; beyond, frames are indexed by approximate.engine (an engine of
  // matching/search/engine_registry.h) in blocks of block_frames merged as they grow (sizes
  // block_frames x 2^m, at most one of each), and only the newest unindexed frames
  // (< block_frames) are scanned exactly. The index is built on the rows of the first
  // descriptor of the map that has one (Hamming or L2; SAD's L1 has none: a map of SAD alone
  // is scanned exactly at any size).
  int exact_limit = 20000;
  int block_frames = 4096;
  // Merges of two blocks into one are built on a background thread while the frames go on
  // being searched in the two old blocks, so no frame waits for a large index build (a merge
  // to 500,000 rows takes seconds). The candidates then depend on when a merge finishes: false
  // builds merges in AddFrame instead, for repeatable results (at the cost of those waits).
  bool background_merges = true;
  // The engine and settings of the blocks' indexes; its k is the per-block candidate count
  // (>= candidates). Throws from Check() when the engine needs FAISS and the build has none.
  ApproximateOptions approximate;
  // Geometric verification and temporal consistency (OpenABLE/verification/verification.h,
  // the Verification_* keys; verification.tolerance: the frames within which references
  // count as neighbours for the consistency). When enabled: each frame's local features are
  // computed in AddFrame and kept (about 20 KB a frame with 500 ORB features); the candidates
  // of a frame are its verification.candidates best at distinct places (more than
  // score_window frames apart), each checked against the frame; a candidate is accepted when
  // it is verified (the threshold is not applied). AddDescriptor and AddToMap, which give no
  // image, are refused.
  VerificationOptions verification;

  // The acceptance threshold of each score when none is given: distance 0.13 (the mean
  // fraction of differing bits of LDB 256 below which every top-1 candidate of KITTI 00 was a
  // loop, bench/bench_online.cc), ratio 0.9 (Match_threshold of the presets, measured across
  // datasets in docs/benchmarks.md).
  static double DefaultThreshold(MatchScore score) {
    return score == MatchScore::kRatio ? 0.9 : 0.13;
  }
  double Threshold() const { return threshold >= 0 ? threshold : DefaultThreshold(score.kind); }
  // Throws InputError naming the field, the value and what was expected.
  void Check() const;
};

// What OnlineDetector::Tune chose for a map (openable_map tune), kept in the map: the
// description, sequence, score and acceptance the search then uses, and the verdict.
struct MapTuning {
  bool tuned = false;
  bool reliable = false;         // the choice's consistency >= min_consistency
  std::string reference, query;  // the sessions it was judged on (reference: the columns)
  std::string time;              // when (ISO 8601 UTC)
  std::string chosen;            // the chosen candidate, "Key=value ..."
  double consistency = 0, distinctiveness = 0, agreement = 0;
  double min_consistency = 0.5;
  std::string candidates_json;  // every candidate with its criteria (AutoJson's list)
  OnlineOptions search;         // the options whose search settings were chosen
  std::vector<double> units;    // the fusion's unit of each descriptor of the choice
  double shift = 0;             // the contrast enhancement's shift of the choice
};

// One loop candidate of a frame.
struct LoopCandidate {
  int frame = -1;          // the earlier frame (its number in the whole map)
  int session = -1;        // its session (an index of OnlineDetector::Sessions())
  int session_frame = -1;  // its frame within that session (frame - the session's first)
  double distance = 0;     // raw sequence distance S(q, j) (Hamming bits or L2, summed over L
                           // frames; early frames scaled as in matching/sequence.h)
  // distance / (L x unit): unit = the descriptor's bit count for binary descriptors (so it is
  // the mean fraction of differing bits, in [0, 1]), and for float descriptors the largest
  // single-frame distance the detector has computed so far. Not the scale of Config.txt's
  // Threshold (which divides by the largest distance of the finished matrix, Eq. 5).
  double normalized = 0;
  // OnlineOptions::score: `normalized`, or the ratio of `distance` to the best candidate
  // outside +-score_window frames of this one (1 without one).
  double score = 0;
  // OnlineOptions::consistency > 0: the best candidates of the n earlier independent queries
  // agree with this one along its diagonal (see OnlineOptions::consistency).
  bool confirmed = false;
  // score <= OnlineOptions::Threshold() and, with consistency, `confirmed`; never on a map
  // whose tuned settings are unreliable (MapTuning) while the search uses them; with
  // verification: `verified`.
  bool accepted = false;
  // Verification (OnlineOptions::verification.enabled): feature matches after the ratio test,
  // inliers of the model kept, the model, whether it reached min_inliers (`geometric`), the
  // streak of the temporal consistency, and whether the candidate passed both (`verified`).
  int matches = 0, inliers = 0;
  GeometricModel model = GeometricModel::kNone;
  bool geometric = false;
  int streak = 0;
  bool verified = false;
};

struct OnlineResult {
  int frame = -1;                         // index of the frame just added (0, 1, ...);
                                          // Query: the query's row
  int session = -1;                       // the session it was added to (Query: -1)
  std::vector<LoopCandidate> candidates;  // best first (ties: earlier frame first); empty
                                          // while no frame is old enough
  bool approximate = false;               // the search used the index blocks
  double describe_seconds = 0;            // AddFrame: describing the image
  double search_seconds = 0;              // searching and bookkeeping (index builds too)
  double verify_seconds = 0;              // verification: features of the frame and checks
};

// Loop candidates frame by frame. Memory: the descriptor rows of every frame (row bytes x
// frames: 32 B a frame for LDB 256 bits, 3.2 MB per 100,000 frames; the sum of the
// descriptors' for a map of several) plus, beyond exact_limit, the approximate indices (see
// MemoryBytes), plus while exact the last L single-frame distance rows of the current
// traversal (L x 4 B a searchable frame). Latency per frame: description, plus one distance
// per searchable frame while exact (linear in the map up to exact_limit, whatever L: the
// sequence sums run along the diagonals as the frames come, matching/sequence.h
// SequenceRowSums), then one index query per block (about log2(frames / block_frames) + 1
// blocks; one more while a merge is built) plus an exact scan of fewer than block_frames
// frames, plus L distances per candidate; every block_frames frames one block of block_frames
// rows is indexed in AddFrame (milliseconds). Not thread-safe for AddFrame; the const members
// may be called while no AddFrame runs.
//
// Rows: a map of one descriptor takes and gives its rows (CV_8U for Hamming and L1, CV_32F
// for L2). A map of several (a fusion, or kept_descriptors) takes and gives each frame's rows
// side by side as bytes, in the order of Channels() (CV_8U, RowWidth() bytes; a float row as
// its 4-byte little-endian floats), as DescribeFrames makes them.
class OnlineDetector {
 public:
  explicit OnlineDetector(const OnlineOptions& options);  // throws InputError on bad options
  ~OnlineDetector();
  OnlineDetector(const OnlineDetector&) = delete;
  OnlineDetector& operator=(const OnlineDetector&) = delete;

  // Describes `image` (CV_8UC1/CV_8UC3 BGR, or CV_32FC1/CV_32FC3 in [0, 1], as a FrameSource
  // gives it; converted to grey as Test_OpenABLE does) and adds it. Throws InputError on an
  // empty image, another type, or an image smaller than the description needs.
  OnlineResult AddFrame(const cv::Mat& image);
  // Adds an already computed row (1 x RowWidth(), RowType()) and searches for it.
  OnlineResult AddDescriptor(const cv::Mat& row);
  // Appends rows (n x RowWidth(), RowType()) as frames Size() .. Size() + n - 1 without
  // searching for them: a map saved from an earlier run (see Descriptors()). Later frames find
  // them as candidates like any other frame.
  void AddToMap(const cv::Mat& rows);
  // AddToMap, the frames named `names` (one per row; their image files, kept in saved maps).
  void AddToMap(const cv::Mat& rows, const std::vector<std::string>& names);
  // Describes `images` (as AddFrame takes them, spread over the cores) and appends them as
  // AddToMap does: a traversal added to a map in bulk. Every image must be of the map's frame
  // size (FrameSize; the first sets it); `names` (one per image, or empty) name them in
  // messages. Throws InputError naming the first image that does not fit, adding none.
  void AddImagesToMap(const std::vector<cv::Mat>& images,
                      const std::vector<std::string>& names = {});
  // The rows of `images` (as AddFrame takes them, described on every core) without adding
  // them: frames of a traversal to query (Query) or to add (AddToMap). Every image must be of
  // the map's frame size (FrameSize; when unknown, of the first image's); `names` (one per
  // image, or empty) name them in messages. Throws InputError naming the first image that
  // does not fit.
  cv::Mat DescribeFrames(const std::vector<cv::Mat>& images,
                         const std::vector<std::string>& names = {}) const;

  // Sessions: a map holds one or more traversals, each a run of consecutive frames with a
  // name and a time (MapSession). StartSession begins one at frame Size() (an empty session
  // begun before is replaced); frames added before any session belong to one named
  // "default". A frame's candidates are every frame of the earlier sessions and the frames of
  // its own session at least `exclusion` frames back; sequences (L) never run across the
  // start of a session. `time`: ISO 8601 UTC, by default now. Throws InputError on a name
  // that is empty, not printable text (CheckSessionName) or already in the map.
  void StartSession(const std::string& name, const std::string& time = "");
  const std::vector<MapSession>& Sessions() const;
  int SessionOf(int frame) const;  // the session holding `frame` (0 .. Size() - 1)

  // Searches the map for each row of `rows` (n x RowWidth(), RowType(): a query traversal, row
  // i its frame i, whose sequences use its own earlier rows) without adding them: every frame
  // of the map is a candidate (no exclusion), or with `sessions` given only the frames of the
  // sessions so named. With a session filter the frames of those sessions are scanned exactly
  // when they number at most exact_limit; beyond, the index's candidates in other sessions
  // are dropped (a query may then get fewer than `candidates`). Rows spread over the cores.
  // Refused with verification (it needs each query's image). Throws InputError on rows of
  // another width or type, an unknown session name, or a damaged loaded map (CheckMap).
  // `progress` (when set) is told the queries done and their count now and then. `matrix`
  // (when given) receives the sequence distances of every query against every frame searched,
  // when the search scans them exactly (QueryMatrix).
  struct QueryMatrix {
    // queries x frames searched: S(q, j) as the search scored it (+inf without a value); empty
    // when the index was used or the matrix would take more than max_bytes.
    cv::Mat1f sums;
    std::vector<int> frames;  // the map frame of each column, in frame order
    std::int64_t max_bytes = std::int64_t{1} << 30;
  };
  std::vector<OnlineResult> Query(const cv::Mat& rows,
                                  const std::vector<std::string>& sessions = {},
                                  const std::function<void(int, int)>& progress = {},
                                  QueryMatrix* matrix = nullptr) const;
  // Query(DescribeFrames(images), sessions).
  std::vector<OnlineResult> QueryImages(const std::vector<cv::Mat>& images,
                                        const std::vector<std::string>& sessions = {}) const;

  // The image file of each frame as AddImagesToMap was told (its `names`; "" for frames added
  // otherwise), kept in saved maps; empty when no frame was named.
  const std::vector<std::string>& FrameFiles() const;

  // "WxH" of the frames given to AddFrame (set by the first one, kept in saved maps; "" when
  // unknown). AddFrame and QueryImages refuse frames of another size.
  const std::string& FrameSize() const;

  const OnlineOptions& Options() const;
  int Size() const;      // frames added
  int RowWidth() const;  // elements per row (bytes for a map of several descriptors)
  int RowType() const;   // CV_8U (Hamming, L1, several descriptors) or CV_32F (L2)
  // Size() x RowWidth(): the stored rows (a view for one descriptor, a copy for several).
  cv::Mat Descriptors() const;
  // The descriptors the map describes every frame with (OnlineOptions::descriptor's, then
  // kept_descriptors'), upper case as the registry names them.
  std::vector<std::string> Channels() const;

  // Chooses the search settings from the data, with no ground truth, as a run with Auto 1
  // does (OpenABLE/tuning/auto.h): the frames of session `query` are matched against those of
  // session `reference` (both must be in the map; the first two sessions when empty) with every
  // candidate of `candidates` (Auto_candidates' syntax; empty: the keys of the default that the
  // map's descriptors allow), each judged by its agreement, and the best becomes this
  // detector's search: descriptor (among Channels()), fusion weights, contrast enhancement,
  // L, the ratio score over +-score_window frames with `threshold` (< 0: the ratio's default)
  // and consistency 1, as the presets accept; the fusion's units and the contrast's shift are
  // those of the chosen matrix. When the chosen candidate's consistency is below
  // `min_consistency` the map is unreliable (MapTuning::reliable false) and accepts nothing
  // while these settings are used. Kept by SaveMap. Candidates may vary Image_descriptor,
  // Fusion_weights, Image_sequences, Contrast_enhancement and Contrast_window only (the rows
  // are described already); others are refused naming the key. Memory: one float per pair of
  // frames of the two sessions per descriptor; `max_frames` > 0 judges on the first
  // max_frames frames of each session. `log` gets one line per candidate. Throws InputError.
  struct TuneOptions {
    std::string reference, query;
    std::string candidates;
    double min_consistency = 0.5;
    double threshold = -1;
    int max_frames = 0;
  };
  MapTuning Tune(const TuneOptions& options,
                 const std::function<void(const std::string&)>& log = {});
  // The settings chosen by Tune (kept in a saved map), or tuned = false.
  const MapTuning& Tuning() const;
  // Makes `tuning`'s search this detector's, with its fusion units and contrast shift (what
  // Tune does once it has chosen; `tuning` of a map of the same descriptors). Throws
  // InputError when its descriptors are not among Channels().
  void UseTuning(const MapTuning& tuning);
  // The rows of descriptor `channel` of Channels() (Size() x its width), a view.
  cv::Mat ChannelRows(int channel) const;
  // Whether the search uses the tuned settings (then an unreliable map accepts nothing).
  bool UsesTuning() const;
  std::int64_t MemoryBytes() const;  // rows + indices held now
  int Blocks() const;                // index blocks in use (0 while exact)
  // Waits for a background merge (background_merges) to finish and installs its index.
  void FinishMerges();

  // Saves the map to `path` so that a later session starts from it (LoadMap): the settings it
  // was made with, every frame's descriptor row, the index blocks (FAISS's serialisation of
  // each; FLANN's are rebuilt on loading) and, with verification, every frame's local
  // features. Waits for a background merge first. Versioned and checksummed
  // (docs/output_formats.md, "Saved maps"); written to a temporary file renamed into place
  // when complete, so an interrupted save leaves the previous file. Throws InputError naming
  // the path when it cannot be written.
  void SaveMap(const std::string& path);

  // What LoadMap did.
  struct LoadedMap {
    int frames = 0;        // frames read: they are frames 0 .. frames - 1 of this detector
    int blocks = 0;        // index blocks in use after loading
    bool rebuilt = false;  // the blocks were built from the rows instead of read
    std::string reason;    // why they were rebuilt (the first index setting that differs)
  };
  // Loads a map written by SaveMap into this detector, which must be empty (Size() == 0).
  // The next frame added is frame `frames`, and finds the loaded frames as candidates like
  // any other: with the options of the detector that saved the map, the candidates of every
  // later frame are those that detector would have given (the verification's temporal
  // consistency starts anew: the first frame after loading has no previous streaks). The
  // description settings (description, patch_size, ldb_bits, sad_patch, grid_x, grid_y) and
  // the descriptors (Channels()) must be the map's; the search may use any of them (a tuned
  // map's settings: MapOptions). With verification enabled the map must hold features of the
  // same kind.
  // When an index setting differs (engine and its build settings, exact_limit, block_frames,
  // exclusion), the saved blocks are set aside and the index built from the rows. Throws
  // InputError beginning with the path: unreadable, not a map, another format version,
  // damaged or truncated (checksum), or made with other description settings.
  //
  // `read` chooses how (map_file.h): by default the file is memory-mapped and its rows and
  // binary_ivf blocks are used where they lie (no copy; other engines' blocks are read from
  // the mapping), and the checksums of the rows and blocks are verified on a background
  // thread: a damaged map is then reported by CheckMap, and by the next call that adds,
  // queries or saves (SaveMap and AppendMap wait for the check). Everything else (header,
  // settings, sessions, features, each index's structure) is checked before returning. Maps
  // of format version 1 are read too, as one session named "default".
  LoadedMap LoadMap(const std::string& path, const MapReadOptions& read = {});
  // Waits for the background check of a loaded map; throws its InputError when the map is
  // damaged. Returns at once when no map was loaded or it was checked.
  void CheckMap() const;

  // Appends the sessions of the map at `path` (made with the same description settings and
  // frame size; session names not already here) after this detector's frames, as frames
  // Size() ..; their rows are indexed as AddToMap does. The merge of two maps: load one,
  // append the other, save. Throws InputError naming the path and what differs, changing
  // nothing.
  void AppendMap(const std::string& path);

 private:
  LoadedMap LoadMapNamed(const std::string& path, const MapReadOptions& read);
  void AppendMapNamed(const std::string& path);
  struct State;
  std::unique_ptr<State> state_;
};

// The options of a detector that loads the map at `path` with its saved index: the
// description settings (descriptors, description, patch size, LDB bits, SAD patch, grid) and
// the index settings (exclusion, exact_limit, block_frames, engine and its build settings) the
// map was made with; the search settings (descriptor, fusion weights, contrast enhancement, L,
// score and its window, threshold, consistency) Tune chose when the map is tuned, else those
// it was saved with (maps of format 3; `base`'s for older maps); everything else from `base`.
// Reads the map's settings only. Throws InputError as LoadMap does, and "no map at PATH
// (create one with openable_map add ...)" when there is none.
OnlineOptions MapOptions(const std::string& path, const OnlineOptions& base = OnlineOptions());

// ---- Batch helpers -------------------------------------------------------------------------

// The absolute path of a network's file (Model_path) as a map keeps it, so that the map finds
// it from another working folder; `path` itself when it cannot be made absolute.
std::string AbsoluteModelPath(const std::string& path);

// The describer of `options` (descriptor, description, grid) and the descriptor it uses.
struct Describer {
  std::unique_ptr<Descriptor> descriptor;
  std::unique_ptr<FrameDescriber> frame;
};
Describer MakeDescriber(const OnlineOptions& options);

// One row per image (images as OnlineDetector::AddFrame takes them), in parallel on `threads`
// threads (0 = all cores). Throws InputError naming the image index.
cv::Mat DescribeImages(const std::vector<cv::Mat>& images, const OnlineOptions& options,
                       int threads = 0);

// Distances between all rows of `rows` (`metric`; by default Hamming for CV_8U, L2 for
// CV_32F; L1 for SAD's byte rows), summed along sequences of L frames (matching/sequence.h;
// `traversal_starts` and `partial` as there), normalised by their largest value (Eq. 5).
// `max_distance` receives that divisor (0 leaves the matrix as is).
cv::Mat1f DistanceMatrix(const cv::Mat& rows, int sequence_length = 1,
                         SequenceDirection direction = SequenceDirection::kForward,
                         const std::vector<int>& traversal_starts = {}, int threads = 0,
                         float* max_distance = nullptr, std::optional<Metric> metric = {},
                         SequencePartial partial = SequencePartial::kAhead);

}  // namespace openable
