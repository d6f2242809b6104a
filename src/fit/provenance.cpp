// Provenance lines of `vertexflow enhance` (provenance.h).
#include "vertexflow/provenance.h"

#include "vertexflow/io.h"

#include <algorithm>
#include <filesystem>

namespace vertexflow {

std::string provenance_line(const ProvenanceRun& run) {
  std::string line = "vertexflow enhance";
  switch (run.mode) {
    case EnhanceMode::Flow:
      line += " --surface input";
      break;
    case EnhanceMode::Smooth:
      line += " --surface smooth";
      break;
    case EnhanceMode::Unsharp:
      line += " --method unsharp";
      break;
    case EnhanceMode::ReferenceFit:
    case EnhanceMode::ReferenceFlow: {
      // One word: records_fit reads the line word by word.
      std::string name = std::filesystem::path(run.reference).filename().string();
      for (char& c : name) {
        if (static_cast<unsigned char>(c) <= 32 || c == 127) c = '?';
      }
      line += " --reference " + (name.empty() ? std::string("?") : name);
      line += run.mode == EnhanceMode::ReferenceFit ? " --reference-method fit" : " --reference-method flow";
      break;
    }
  }
  if (run.assume_on_surface) line += " --assume-on-surface";
  if (run.edge_flips) line += " --edge-flips";
  if (!run.held.empty()) line += " (held: " + run.held + ")";
  return line;
}

bool records_fit(std::string_view comment) {
  std::vector<std::string_view> words;
  while (!comment.empty()) {
    const std::size_t start = comment.find_first_not_of(' ');
    if (start == std::string_view::npos) break;
    comment.remove_prefix(start);
    const std::size_t end = std::min(comment.find(' '), comment.size());
    words.push_back(comment.substr(0, end));
    comment.remove_prefix(end);
  }
  if (words.size() < 4 || words[0] != "vertexflow" || words[1] != "enhance") return false;
  bool fit = false;
  for (std::size_t i = 2; i < words.size(); ++i) {
    if (words[i] == "(held:") return false;  // the vertices were left where they were
    if (i + 1 < words.size() && ((words[i] == "--surface" && words[i + 1] == "smooth") ||
                                 (words[i] == "--reference-method" && words[i + 1] == "fit")))
      fit = true;
  }
  return fit;
}

const std::string* find_fit_provenance(const std::vector<std::string>& comments) {
  const auto it = std::find_if(comments.begin(), comments.end(), [](const std::string& c) { return records_fit(c); });
  return it == comments.end() ? nullptr : &*it;
}

void append_provenance(std::vector<std::string>& comments, std::string line) {
  while (!comments.empty() && comments.size() >= kMaxCommentLines) {
    const auto unfit =
        std::find_if(comments.begin(), comments.end(), [](const std::string& c) { return !records_fit(c); });
    comments.erase(unfit != comments.end() ? unfit : comments.begin());
  }
  comments.push_back(std::move(line));
}

}  // namespace vertexflow
