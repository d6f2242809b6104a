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

namespace {

// Takes `word` off the front of `line` if it is there.
bool consume(std::string_view& line, std::string_view word) {
  if (line.substr(0, word.size()) != word) return false;
  line.remove_prefix(word.size());
  return true;
}

}  // namespace

// Only a line exactly as provenance_line writes it counts: any other comment that merely
// mentions "--surface smooth" would make smooth mode hold a mesh no fit ever touched.
bool records_fit(std::string_view comment) {
  std::string_view rest = comment;
  if (!consume(rest, "vertexflow enhance ")) return false;
  if (!consume(rest, "--surface smooth")) {
    // " --reference NAME --reference-method fit": NAME one word of printable characters.
    if (!consume(rest, "--reference ")) return false;
    const std::size_t name_end = rest.find(' ');
    if (name_end == 0 || name_end == std::string_view::npos) return false;
    for (const char c : rest.substr(0, name_end))
      if (static_cast<unsigned char>(c) <= 32 || c == 127) return false;
    rest.remove_prefix(name_end);
    if (!consume(rest, " --reference-method fit")) return false;
  }
  consume(rest, " --assume-on-surface");
  consume(rest, " --edge-flips");
  return rest.empty();  // a " (held: ...)" line records no fit: the vertices stayed
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
