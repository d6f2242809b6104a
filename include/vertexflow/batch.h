// The batch engine of `vertexflow batch` and of the Python module's batch() and enhance_file():
// the enhance engine (enhance.h), in any mode, over many files, each written atomically to an
// output directory, a failing file recorded and skipped, existing outputs skipped unless forced
// (resumable), and a summary table (CSV and JSON) with one row per file.
//
// The files come from directories (every file with a mesh extension, io.h), glob patterns,
// file names, or a manifest of (input, reference, output) rows; reference modes take each
// file's reference from its manifest row or from a directory of references matched by file
// stem. Outputs are the bytes `vertexflow enhance IN OUT [--reference REF]` writes for the same
// options: the same read, the same enhance call, the same write_mesh. Results do not depend on
// the jobs or threads (the library's results do not depend on the thread count).
#pragma once

#include "vertexflow/enhance.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace vertexflow {

/// One file of a batch: what happened and what it measured. Metrics are those of `enhance
/// --report` (enhance_metrics), NaN or -1 when not measured (failed, or metrics off).
struct BatchRow {
  std::string input;
  std::string output;
  std::string reference;  ///< empty without one
  std::string mode;       ///< enhance_mode_name of the file's mode ("flow", "reference", ...)
  /// "done", "skipped" (output existed) or "failed". A skipped file keeps the measurements and
  /// seconds of the run that wrote its output, from the batch_summary.json found in the output
  /// directory. Where that summary has no complete row for it (none, a damaged one, or a row
  /// without metrics when metrics are on), its metrics are measured again from its input and the
  /// output on disk; the seconds are then this run's and limited_vertices (which only the run
  /// that wrote the output knew) stays -1. So a resumed batch's summary has every output's
  /// numbers.
  std::string status;
  std::string error;     ///< the one-line error of a failed file ("FILE: problem")
  std::string warnings;  ///< reading and enhance warnings, "; "-separated
  long long vertices = -1, faces = -1;
  double seconds_read = 0, seconds_enhance = 0, seconds_metrics = 0, seconds_write = 0, seconds_total = 0;
  long long flipped_faces = -1;
  double rho_input = std::nan(""), rho_result = std::nan("");
  double cv_input = std::nan(""), cv_result = std::nan("");
  double displacement_mean = std::nan(""), displacement_max = std::nan("");  ///< mean input edge lengths
  long long limited_vertices = -1;
  /// Reference modes: the two-sided mean and Hausdorff distances of the input and the result to
  /// the reference (enhance_metrics' distance_to_reference), in the meshes' units.
  double distance_mean_input = std::nan(""), distance_mean_result = std::nan("");
  double hausdorff_input = std::nan(""), hausdorff_result = std::nan("");
};

/// The options of one file's run.
struct BatchFileOptions {
  EnhanceOptions enhance;
  /// Overwrite an existing output (otherwise the file is skipped: resumable batches).
  bool force = false;
  /// Measure rho, CV, flips, displacement and the distances to the reference
  /// (enhance_metrics). Without it those stay NaN / -1.
  bool metrics = true;
  /// TBB threads for this file (a task_arena of this size); 0: all cores.
  int threads = 0;
};

/// Reads `input` (and `reference`, when not empty), enhances it, writes `output` atomically (its
/// directory created if need be) and
/// measures the result. Never throws for a problem of the file (unreadable, not a mesh, a mesh
/// the method refuses, a missing reference, an output that cannot be written): the row says
/// "failed" and gives the error. An existing output is skipped unless options.force. An output
/// that is the input or the reference is refused.
BatchRow enhance_file(const std::filesystem::path& input, const std::filesystem::path& output,
                      const BatchFileOptions& options, const std::filesystem::path& reference = {});

/// Progress after each file.
struct BatchProgress {
  std::size_t finished = 0;  ///< files finished (done, skipped or failed)
  std::size_t total = 0;
  std::size_t failed = 0;
  const BatchRow* row = nullptr;  ///< the file just finished
  double elapsed = 0;             ///< seconds since the batch started
  double eta = -1;                ///< estimated seconds left (-1: not yet known)
};

/// One file to do: its input, its reference (empty: none) and its output (empty: the output
/// directory and the input's file name).
struct BatchItem {
  std::filesystem::path input;
  std::filesystem::path reference;
  std::filesystem::path output;
};

struct BatchOptions {
  /// Directories (every non-hidden entry with a mesh extension that is not a directory, sorted
  /// by name), glob patterns (glob(3), sorted; its matches with a mesh extension that are not
  /// directories) or files. So a batch's own batch_summary.csv and .json are never inputs, and a
  /// dangling link, a FIFO or a device named *.obj is a failed row in both modes. Ignored when
  /// `items` is not empty.
  std::vector<std::string> inputs;
  /// The files as rows (read_batch_manifest), instead of `inputs`.
  std::vector<BatchItem> items;
  /// For a reference mode without a manifest: each input's reference is the file of this
  /// directory with the input's stem (any mesh extension). A file without one fails.
  std::filesystem::path reference_dir;
  std::filesystem::path output_dir;
  /// Files processed at once (threads), each with `file.threads` TBB threads (0: the cores
  /// divided among the jobs).
  int jobs = 1;
  BatchFileOptions file;
  /// Called after every file from the thread that finished it, one call at a time. An exception
  /// it throws stops the batch at the next file boundary (the files being processed finish, no
  /// other starts, progress is not called again), the summary is written with the files finished
  /// (so a rerun resumes), and run_batch rethrows it: how a front end cancels a batch.
  std::function<void(const BatchProgress&)> progress;
  /// Called with each warning about the batch as a whole, one line naming its file (an earlier
  /// batch_summary.json that cannot be read), from the calling thread before any file runs.
  std::function<void(const std::string&)> warning;
  /// Write batch_summary.csv and batch_summary.json into output_dir.
  bool write_summary = true;
  /// How the options' errors name an option (the front end's words, enhance.h).
  OptionNaming naming = OptionNaming::Cpp;
};

struct BatchSummary {
  std::vector<BatchRow> rows;  ///< in the order of the input list
  std::size_t done = 0, skipped = 0, failed = 0;
  double seconds = 0;
  std::filesystem::path csv, json;  ///< the summary files written (empty if none)
};

/// The input list of a batch, in order (see BatchOptions::inputs). Throws IoError for a pattern
/// that matches no mesh file name or a path that does not exist.
std::vector<std::filesystem::path> batch_inputs(const std::vector<std::string>& inputs);

/// Reads a manifest: CSV with a header row naming the columns input, reference and output
/// (reference and output may be missing or empty), or JSON, a list of objects with those keys.
/// Relative paths are taken relative to the manifest's directory. Throws IoError naming the
/// file and the line (or row) of a problem.
std::vector<BatchItem> read_batch_manifest(const std::filesystem::path& manifest);

/// The files of a batch as run_batch takes them: `items`, or the files of `inputs`; each output
/// resolved (empty: output_dir and the input's file name) and, with a reference_dir, each
/// reference found by stem (empty where none is). Throws IoError as batch_inputs, and for a
/// reference_dir that is not a directory.
std::vector<BatchItem> batch_items(const BatchOptions& options);

/// Runs the batch. Throws IoError only for problems of the batch as a whole (no inputs, an
/// output directory that cannot be created, an unreadable manifest) and std::invalid_argument
/// for bad options; a bad file is a failed row.
BatchSummary run_batch(const BatchOptions& options);

/// A row as JSON (NaN as null) and the summary's CSV text.
nlohmann::json to_json(const BatchRow& row);
std::string batch_csv(const std::vector<BatchRow>& rows);

}  // namespace vertexflow
