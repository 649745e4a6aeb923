// Which part of a distance matrix an evaluation looks at, and which cells are candidates.
#pragma once

namespace openable {

// The evaluated block of a distance matrix (evaluation.md, both protocols).
struct EvaluationLayout {
  enum class Kind {
    // One sequence: a square N x N matrix; the candidates of query q are the earlier frames
    // j <= q - exclusion (recent frames always look alike and are not loops).
    kLoopClosure,
    // Query against reference: rows are query frames, columns reference frames; every
    // reference frame is a candidate. The lower-left block of a two-traversal run
    // (rows N1.., columns 0..N1-1), or a non-square matrix as a whole.
    kQueryReference,
  };
  Kind kind = Kind::kLoopClosure;
  int queries = 0;     // rows of the block
  int references = 0;  // columns of the block
  int row_offset = 0;  // first row of the block in the full matrix
  int col_offset = 0;  // first column of the block in the full matrix

  // Layout of a square matrix of `frames` frames, one sequence.
  static EvaluationLayout LoopClosure(int frames) {
    return {Kind::kLoopClosure, frames, frames, 0, 0};
  }
  // Layout of the cross block of a square matrix over two concatenated traversals:
  // `reference_frames` first, then `query_frames`.
  static EvaluationLayout TwoTraversals(int reference_frames, int query_frames) {
    return {Kind::kQueryReference, query_frames, reference_frames, reference_frames, 0};
  }
  // Layout of a queries x references matrix taken whole.
  static EvaluationLayout QueryReference(int queries, int references) {
    return {Kind::kQueryReference, queries, references, 0, 0};
  }
  // Query q's candidates are the block's columns [0, CandidateEnd(q, exclusion)): every
  // reference, or with one sequence the frames at least `exclusion` back.
  int CandidateEnd(int q, int exclusion) const {
    if (kind == Kind::kQueryReference) return references;
    const int end = q - exclusion + 1;
    return end < 0 ? 0 : end > references ? references : end;
  }
};

}  // namespace openable
