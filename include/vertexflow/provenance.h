// Provenance: the comment line (Mesh::comments, io.h) that each run of `vertexflow enhance`
// adds to its output, and how smooth mode reads it back.
//
// Smooth mode (fit.h) assumes the input's vertices lie on the true surface. After a fit (smooth
// mode, or reference mode's fit) they lie off the surface the faces inscribe, and geometry
// cannot tell such a mesh from an inscribed one: a second run of smooth mode moves it further
// out (bunny_adaptive: -30% mean distance on the first run, then +37% on the second). The output's
// comments say what placed the vertices, so a later run can hold it.
//
// The lines, one per run, appended after the input's own comments:
//   vertexflow enhance --surface input [--edge-flips]             the paper's flow
//   vertexflow enhance --reference NAME --reference-method fit [--edge-flips]
//   vertexflow enhance --reference NAME --reference-method flow   the flow on the reference
//   vertexflow enhance --surface smooth [--assume-on-surface] [--edge-flips]
//   vertexflow enhance --surface smooth (held: REASON)            smooth mode held the input
//   vertexflow enhance --surface input (held: REASON)             the flow held it (input_check.h)
//   vertexflow enhance --method unsharp
// NAME is the reference's file name without its directories, with blanks and control
// characters replaced by '?', so that the line stays one line of space-separated words ('?' for
// a reference without a name, as the Python module's arrays).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace vertexflow {

/// The enhance mode a provenance line records.
enum class EnhanceMode {
  Flow,           ///< the paper's flow over the input surface (`--surface input`)
  ReferenceFit,   ///< reference mode, fit (`--reference DENSE`)
  ReferenceFlow,  ///< the paper's flow on the reference (`--reference-method flow`)
  Smooth,         ///< smooth mode (`--surface smooth`)
  Unsharp,        ///< the unsharp-mask baseline (`--method unsharp`)
};

/// What a provenance line says about one run, besides its mode.
struct ProvenanceRun {
  EnhanceMode mode = EnhanceMode::Flow;
  /// ReferenceFit and ReferenceFlow: the reference's path (only its file name is written).
  std::string reference;
  bool edge_flips = false;
  bool assume_on_surface = false;
  /// Smooth mode or the flow held the input unchanged; the reason, e.g. "already fitted" or
  /// "decimated" (hold_reason_name, input_check.h; non-empty means held, and the line then
  /// records no fit).
  std::string held;
};

/// The line for `run`, in the format above.
std::string provenance_line(const ProvenanceRun& run);

/// Whether `comment` records a run that placed the vertices off the surface the faces inscribe:
/// a smooth-mode fit (not held) or a reference-mode fit. The paper's flow (`--surface input`,
/// also on a reference) keeps the vertices on the surface it flows over, and the unsharp mask
/// moves them to a new shape whose vertices are its own; neither counts.
bool records_fit(std::string_view comment);

/// The first of `comments` that records_fit, or nullptr.
const std::string* find_fit_provenance(const std::vector<std::string>& comments);

/// Appends `line` to `comments`, keeping at most kMaxCommentLines (io.h) so that a reader keeps
/// them all: when full, the oldest line that records no fit is dropped (the oldest line if all
/// do), so a fit stays visible however long the chain.
void append_provenance(std::vector<std::string>& comments, std::string line);

}  // namespace vertexflow
