#include "vertexflow/reference_surface.h"

#include <tbb/task_group.h>

#include <atomic>
#include <map>
#include <mutex>
#include <stdexcept>
#include <tuple>

namespace vertexflow {
namespace {

// What a build cut short by a cancelled task group throws; TBB rethrows the sibling's exception,
// so this one is never seen.
struct CancelledBuild : std::runtime_error {
  CancelledBuild() : std::runtime_error("reference surface: a build was cancelled") {}
};

}  // namespace

struct ReferenceSurface::Impl {
  Vertices V;
  Faces F;
  std::string name;
  std::once_flag tree_once;
  std::unique_ptr<DistanceQuery> tree;
  std::atomic<int> trees_built{0};
  std::mutex samples_mutex;
  // std::map: its nodes do not move, so a returned reference stays valid as others are added.
  std::map<std::tuple<Index, std::uint64_t, bool, bool, Index>, SurfaceSamples> samples;
};

ReferenceSurface::ReferenceSurface(Vertices V, Faces F, std::string name) : impl_(std::make_unique<Impl>()) {
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument("reference surface: the reference is empty");
  if (!V.allFinite())
    throw std::invalid_argument("reference surface: a vertex of the reference has a non-finite coordinate");
  impl_->V = std::move(V);
  impl_->F = std::move(F);
  impl_->name = std::move(name);
}

ReferenceSurface::~ReferenceSurface() = default;
ReferenceSurface::ReferenceSurface(ReferenceSurface&&) noexcept = default;
ReferenceSurface& ReferenceSurface::operator=(ReferenceSurface&&) noexcept = default;

const Vertices& ReferenceSurface::vertices() const {
  return impl_->V;
}
const Faces& ReferenceSurface::faces() const {
  return impl_->F;
}
const std::string& ReferenceSurface::name() const {
  return impl_->name;
}

const DistanceQuery& ReferenceSurface::distance_query() const {
  std::call_once(impl_->tree_once, [this] {
    // Over the reference's own V and F, which live as long as the tree: no second copy.
    auto tree = std::make_unique<DistanceQuery>(impl_->V, impl_->F, DistanceQuery::Borrow{});
    // Called in a TBB task whose group is being cancelled (a sibling branch of a parallel_invoke
    // threw), the build's own parallel loops return early without an error: that tree may be
    // missing a part. Not kept, and not marked built, so the next call builds it whole.
    if (tbb::is_current_task_group_canceling()) throw CancelledBuild();
    impl_->tree = std::move(tree);
    ++impl_->trees_built;
  });
  return *impl_->tree;
}

const SurfaceSamples& ReferenceSurface::samples(const SamplingOptions& options) const {
  const auto key = std::make_tuple(options.samples, options.seed, options.vertices, options.edge_midpoints,
                                   options.max_vertices_and_midpoints);
  {
    const std::lock_guard lock(impl_->samples_mutex);
    const auto it = impl_->samples.find(key);
    if (it != impl_->samples.end()) return it->second;
  }
  // Drawn outside the lock (it takes a while on a dense S); a second caller with the same
  // options meanwhile draws the same samples, and the first stored is kept.
  SurfaceSamples drawn = sample_surface(impl_->V, impl_->F, options);
  if (tbb::is_current_task_group_canceling()) throw CancelledBuild();  // as for the tree
  const std::lock_guard lock(impl_->samples_mutex);
  return impl_->samples.try_emplace(key, std::move(drawn)).first->second;
}

int ReferenceSurface::trees_built() const {
  return impl_->trees_built.load();
}

std::size_t ReferenceSurface::memory_bytes() const {
  std::size_t bytes = static_cast<std::size_t>(impl_->V.size()) * sizeof(double) +
                      static_cast<std::size_t>(impl_->F.size()) * sizeof(Index);
  if (impl_->trees_built.load() > 0) bytes += impl_->tree->memory_bytes();
  const std::lock_guard lock(impl_->samples_mutex);
  for (const auto& [key, drawn] : impl_->samples)
    bytes += static_cast<std::size_t>(drawn.points.size()) * sizeof(double);
  return bytes;
}

}  // namespace vertexflow
