// The library's two ways in for programs that do not go through Config.txt:
//
//  - OnlineDetector: a SLAM system feeds frames one by one and gets, for each, its loop
//    candidates among earlier frames.
//  - Batch helpers: describe a set of images, compute the normalised distance matrix (with
//    sequences), as Test_OpenABLE does from a configuration.
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
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "OpenABLE/describe/describe.h"
#include "OpenABLE/online/map_file.h"
#include "descriptors/descriptor.h"
#include "OpenABLE/verification/verification.h"
#include "matching/search/approximate.h"
#include "matching/distances.h"
#include "matching/score.h"
#include "matching/sequence.h"

namespace openable {

struct OnlineOptions {
  // Description: the descriptor and its settings, the struct of a run's keys Image_descriptor,
  // Patch_size, Ldb_bits and Sad_patch (descriptors/descriptor.h: name "LDB", patch 64, 256
  // bits; sad_patch for SAD, DescribeImages only), and how a frame is cut (Description_type,
  // Grid_x, Grid_y).
  DescriptorOptions descriptor;
  DescriptionType description = DescriptionType::kGlobal;
  int grid_x = 1, grid_y = 1;
  // Matching.
  // L (the key Image_sequences): frames summed along the diagonal. A candidate among the first
  // L - 1 frames has fewer terms, scaled up to L (Sequence_partial scale): the frames after a
  // query, which a batch run's default (ahead) reads, are not known yet.
  int sequence_length = 1;
  int exclusion = 100;      // frame q's candidates are frames j <= q - exclusion (>= 1)
  int candidates = 5;       // candidates returned per frame (the k best), >= 1
  // The confidence of a candidate (matching/score.h, the key Match_score): its normalised
  // distance, or the ratio of its distance to the best candidate more than score_window
  // frames away from it (the rivals are the candidates the search scored: every searchable
  // frame while exact, the approximate candidates beyond).
  MatchScore score = MatchScore::kDistance;
  int score_window = 10;  // >= 0
  // A candidate is accepted when its score is <= threshold (see LoopCandidate). Default, for
  // the distance score: on KITTI 00 frames 0-1699 with LDB 256 bits, every top-1 candidate up
  // to 0.137 (L = 1) and 0.17 (L = 5, 10) is a true loop (bench/bench_online.cc,
  // docs/library.md). With the ratio score choose it anew (docs/library.md gives figures).
  double threshold = 0.13;
  // Search: exact (every earlier frame) while the searchable map holds at most exact_limit
  // frames; beyond, frames are indexed by approximate.engine (an engine of
  // matching/search/engine_registry.h) in blocks of block_frames merged as they grow (sizes
  // block_frames x 2^m, at most one of each), and only the newest unindexed frames
  // (< block_frames) are scanned exactly.
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
  // Throws InputError naming the field, the value and what was expected.
  void Check() const;
};

// One loop candidate of a frame.
struct LoopCandidate {
  int frame = -1;         // the earlier frame (its number in the whole map)
  int session = -1;       // its session (an index of OnlineDetector::Sessions())
  int session_frame = -1; // its frame within that session (frame - the session's first)
  double distance = 0;    // raw sequence distance S(q, j) (Hamming bits or L2, summed over L
                          // frames; early frames scaled as in matching/sequence.h)
  // distance / (L x unit): unit = the descriptor's bit count for binary descriptors (so it is
  // the mean fraction of differing bits, in [0, 1]), and for float descriptors the largest
  // single-frame distance the detector has computed so far. Not the scale of Config.txt's
  // Threshold (which divides by the largest distance of the finished matrix, Eq. 5).
  double normalized = 0;
  // OnlineOptions::score: `normalized`, or the ratio of `distance` to the best candidate
  // outside +-score_window frames of this one (1 without one).
  double score = 0;
  // score <= OnlineOptions::threshold; with verification: `verified`.
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
  int frame = -1;                            // index of the frame just added (0, 1, ...);
                                             // Query: the query's row
  int session = -1;                          // the session it was added to (Query: -1)
  std::vector<LoopCandidate> candidates;     // best first (ties: earlier frame first); empty
                                             // while no frame is old enough
  bool approximate = false;                  // the search used the index blocks
  double describe_seconds = 0;               // AddFrame: describing the image
  double search_seconds = 0;                 // searching and bookkeeping (index builds too)
  double verify_seconds = 0;                 // verification: features of the frame and checks
};

// Loop candidates frame by frame. Memory: the descriptor rows of every frame (row bytes x
// frames: 32 B a frame for LDB 256 bits, 3.2 MB per 100,000 frames) plus, beyond exact_limit,
// the approximate indices (see MemoryBytes). Latency per frame: description, plus L distances per
// searchable frame while exact (linear in the map up to exact_limit), then one index query per
// block (about log2(frames / block_frames) + 1 blocks; one more while a merge is built) plus
// an exact scan of fewer than block_frames frames, plus L distances per candidate; every
// block_frames frames one block of block_frames rows is indexed in AddFrame (milliseconds). Not
// thread-safe for AddFrame; the const members may be called while no AddFrame runs.
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
  // Adds an already computed row (1 x RowWidth(), RowType()).
  OnlineResult AddDescriptor(const cv::Mat& row);
  // Appends rows (n x RowWidth(), RowType()) as frames Size() .. Size() + n - 1 without
  // searching for them: a map saved from an earlier run (see Descriptors()). Later frames find
  // them as candidates like any other frame.
  void AddToMap(const cv::Mat& rows);
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
  int SessionOf(int frame) const;   // the session holding `frame` (0 .. Size() - 1)

  // Searches the map for each row of `rows` (n x RowWidth(), RowType(): a query traversal, row
  // i its frame i, whose sequences use its own earlier rows) without adding them: every frame
  // of the map is a candidate (no exclusion), or with `sessions` given only the frames of the
  // sessions so named. With a session filter the frames of those sessions are scanned exactly
  // when they number at most exact_limit; beyond, the index's candidates in other sessions
  // are dropped (a query may then get fewer than `candidates`). Rows spread over the cores.
  // Refused with verification (it needs each query's image). Throws InputError on rows of
  // another width or type, an unknown session name, or a damaged loaded map (CheckMap).
  std::vector<OnlineResult> Query(const cv::Mat& rows,
                                  const std::vector<std::string>& sessions = {}) const;
  // Query(DescribeFrames(images), sessions).
  std::vector<OnlineResult> QueryImages(const std::vector<cv::Mat>& images,
                                        const std::vector<std::string>& sessions = {}) const;

  // "WxH" of the frames given to AddFrame (set by the first one, kept in saved maps; "" when
  // unknown). AddFrame and QueryImages refuse frames of another size.
  const std::string& FrameSize() const;

  const OnlineOptions& Options() const;
  int Size() const;                 // frames added
  int RowWidth() const;             // elements per row
  int RowType() const;              // CV_8U (Hamming) or CV_32F (L2)
  cv::Mat Descriptors() const;      // Size() x RowWidth(), a view of the stored rows
  std::int64_t MemoryBytes() const; // rows + indices held now
  int Blocks() const;               // index blocks in use (0 while exact)
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
  // description settings (descriptor, description, patch_size, ldb_bits, grid_x, grid_y) must
  // be the map's, and with verification enabled the map must hold features of the same kind.
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
  struct State;
  std::unique_ptr<State> state_;
};

// The options of a detector that loads the map at `path` with its saved index: the
// description settings (descriptor, description, patch size, LDB bits, grid) and the index
// settings (exclusion, exact_limit, block_frames, engine and its build settings) the map was
// made with, everything else from `base`. Reads the map's settings only. Throws InputError as
// LoadMap does.
OnlineOptions MapOptions(const std::string& path, const OnlineOptions& base = {});

// ---- Batch helpers -------------------------------------------------------------------------

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
