// Attributes of moved vertices (transport.h; docs/attributes.md).
#include "attributes/transport.h"

#include "mesh/closest_point.h"
#include "mesh/fan_walk.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace vertexflow::attributes_detail {
namespace {

// The corner of face `face` (a row of input.F) at vertex v.
int corner_at(const Faces& F, Index face, Index v) {
  for (int k = 0; k < 3; ++k)
    if (F(face, k) == v) return k;
  return -1;
}

bool is_chart_label(const AttributeChannel& c) {
  return c.role == AttributeRole::Label && c.name != "smoothing";
}

// Whether the edge (a, b) between input faces f and g is a chart boundary (transport.h).
bool separates_charts(const MeshAttributes& attributes, const Faces& F, Index f, Index g, Index a, Index b) {
  for (const CornerChannel& c : attributes.corner) {
    if (c.channel.role != AttributeRole::TexCoord) continue;
    for (const Index v : {a, b}) {
      const int kf = corner_at(F, f, v), kg = corner_at(F, g, v);
      if (kf >= 0 && kg >= 0 && c.corners(f, kf) != c.corners(g, kg)) return true;
    }
  }
  for (const AttributeChannel& c : attributes.face)
    if (is_chart_label(c) && c.values.row(f) != c.values.row(g)) return true;
  return false;
}

// Per topology edge: 1 where it is a chart boundary.
std::vector<char> boundary_flags(const Mesh& input, const std::vector<Index>& faces, const Topology& topology) {
  std::vector<char> flag(static_cast<std::size_t>(topology.num_edges()), 0);
  for (Index f = 0; f < topology.num_faces; ++f)
    for (int k = 0; k < 3; ++k) {
      const Index g = topology.face_adjacency(f, k);
      if (g <= f) continue;
      const Index a = input.F(faces[static_cast<std::size_t>(f)], k);
      const Index b = input.F(faces[static_cast<std::size_t>(f)], (k + 1) % 3);
      if (separates_charts(input.attributes, input.F, faces[static_cast<std::size_t>(f)],
                           faces[static_cast<std::size_t>(g)], a, b))
        flag[static_cast<std::size_t>(topology.face_edges(f, k))] = 1;
    }
  return flag;
}

struct Location {
  Index face = -1;  // local (index into `faces`)
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  double distance = std::numeric_limits<double>::infinity();
};

// The closest point to p on the faces reachable from `seeds` without crossing a chart boundary:
// a best-first walk that expands faces within `slack` of the best distance found, at most
// kMaxFaces of them (a walk, not a global query, so that it never jumps through a thin wall).
class Walker {
 public:
  Walker(const Mesh& input, const std::vector<Index>& faces, const Topology& topology, const std::vector<char>& flag,
         double slack)
      : input_(input),
        faces_(faces),
        topology_(topology),
        flag_(flag),
        slack_(slack),
        seen_(static_cast<std::size_t>(topology.num_faces), 0) {}

  Location locate(const Eigen::Vector3d& p, const std::vector<Index>& seeds) {
    Location best;
    open_.clear();
    auto visit = [&](Index f) {
      if (seen_[static_cast<std::size_t>(f)]) return;
      seen_[static_cast<std::size_t>(f)] = 1;
      touched_.push_back(f);
      const Index face = faces_[static_cast<std::size_t>(f)];
      const Eigen::Vector3d a = input_.V.row(input_.F(face, 0)), b = input_.V.row(input_.F(face, 1)),
                            d = input_.V.row(input_.F(face, 2));
      const TrianglePoint t = closest_point_on_triangle(p, a, b, d);
      // A degenerate face is never the answer, but the walk goes on through it.
      const double distance = t.valid ? (t.point - p).norm() : (a - p).norm();
      if (t.valid && distance < best.distance) best = {f, t.barycentric, distance};
      open_.emplace_back(distance, f);
      std::push_heap(open_.begin(), open_.end(), std::greater<>());
    };
    for (const Index f : seeds) visit(f);
    constexpr std::size_t kMaxFaces = 4096;
    while (!open_.empty() && touched_.size() < kMaxFaces) {
      std::pop_heap(open_.begin(), open_.end(), std::greater<>());
      const auto [distance, f] = open_.back();
      open_.pop_back();
      if (distance > best.distance + slack_) break;
      for (int k = 0; k < 3; ++k) {
        const Index g = topology_.face_adjacency(f, k);
        if (g >= 0 && !flag_[static_cast<std::size_t>(topology_.face_edges(f, k))]) visit(g);
      }
    }
    for (const Index f : touched_) seen_[static_cast<std::size_t>(f)] = 0;
    touched_.clear();
    return best;
  }

 private:
  const Mesh& input_;
  const std::vector<Index>& faces_;
  const Topology& topology_;
  const std::vector<char>& flag_;
  double slack_;
  std::vector<char> seen_;
  std::vector<Index> touched_;
  std::vector<std::pair<double, Index>> open_;  // a min-heap of (distance, face), kept for reuse
};

// The faces around v (local ids) grouped into wedges: connected across edges at v that are no
// chart boundary.
std::vector<std::vector<Index>> wedges_of(Index v, const Topology& topology, const std::vector<char>& flag) {
  const Index* begin = topology.vertex_faces.data() + topology.face_offsets[static_cast<std::size_t>(v)];
  const Index* end = topology.vertex_faces.data() + topology.face_offsets[static_cast<std::size_t>(v) + 1];
  const auto n = static_cast<std::size_t>(end - begin);
  // Most vertices have no chart boundary at them: one wedge. (Boundary and non-manifold fans
  // need the general case, as their faces may not all be connected.)
  bool plain = topology.is_manifold_vertex[static_cast<std::size_t>(v)] &&
               !topology.is_boundary_vertex[static_cast<std::size_t>(v)];
  for (const Index* f = begin; f != end && plain; ++f)
    for (int k = 0; k < 3; ++k) plain = plain && !flag[static_cast<std::size_t>(topology.face_edges(*f, k))];
  if (plain) return {std::vector<Index>(begin, end)};
  std::vector<std::size_t> parent(n);
  for (std::size_t i = 0; i < n; ++i) parent[i] = i;
  auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Index f = begin[i];
    for (int k = 0; k < 3; ++k) {
      const Index g = topology.face_adjacency(f, k);
      const Index e = topology.face_edges(f, k);
      if (g < 0 || flag[static_cast<std::size_t>(e)] || (topology.edges(e, 0) != v && topology.edges(e, 1) != v))
        continue;
      const std::size_t j = static_cast<std::size_t>(std::find(begin, end, g) - begin);
      if (j < n) parent[root(i)] = root(j);
    }
  }
  std::vector<std::vector<Index>> wedges;
  std::vector<std::size_t> wedge_of_root(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t r = root(i);
    if (wedge_of_root[r] == n) {
      wedge_of_root[r] = wedges.size();
      wedges.emplace_back();
    }
    wedges[wedge_of_root[r]].push_back(begin[i]);
  }
  return wedges;
}

bool interpolated(const AttributeChannel& c) {
  return c.role != AttributeRole::Label && c.role != AttributeRole::Normal;
}

// Σ b_k values(row_k), finished by role: rounded to an integer type, weights renormalised.
Eigen::RowVectorXd blend(const AttributeChannel& c, const std::array<Eigen::Index, 3>& rows, const Eigen::Vector3d& b) {
  Eigen::RowVectorXd value = Eigen::RowVectorXd::Zero(c.width());
  for (int k = 0; k < 3; ++k) value += b[k] * c.values.row(rows[static_cast<std::size_t>(k)]);
  if (c.role == AttributeRole::Weights) {
    // Sum 1, or for normalised integers (glTF's unsigned byte and short weights) the type's
    // largest value, which stands for 1.
    const double one = is_integer_type(c.type) ? to_scalar_type(1e300, c.type) : 1.0;
    const double sum = value.sum();
    if (sum > 0) value *= one / sum;
  }
  if (is_integer_type(c.type))
    for (int k = 0; k < c.width(); ++k) value[k] = to_scalar_type(value[k], c.type);
  return value;
}

// Area-weighted unit normals of faces `F` at V: per vertex (`per_vertex`), or per row of a
// corner table. Rows whose faces did not change keep `old` exactly, and the orientation of
// `old` is kept (inward normals stay inward).
void recompute_normals(AttributeChannel& channel,
                       const Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>* corners,
                       const Vertices& V, const Faces& F, const std::vector<char>& face_changed) {
  const Eigen::Index rows = channel.rows();
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(rows, 3);
  std::vector<char> changed(static_cast<std::size_t>(rows), 0);
  for (Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d n = face_normal(V, F, f);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index r = corners ? (*corners)(f, k) : F(f, k);
      if (r < 0 || r >= rows) continue;
      sum.row(r) += n.transpose();
      if (face_changed[static_cast<std::size_t>(f)]) changed[static_cast<std::size_t>(r)] = 1;
    }
  }
  double agreement = 0;  // the input's orientation against the faces'
  for (Eigen::Index r = 0; r < rows; ++r) agreement += channel.values.row(r).head(3).dot(sum.row(r));
  const double sign = agreement < 0 ? -1.0 : 1.0;
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double length = sum.row(r).norm();
    if (!changed[static_cast<std::size_t>(r)] || !(length > 0)) continue;
    channel.values.row(r).head(3) = sign * sum.row(r) / length;
  }
}

}  // namespace

ChartBoundaries chart_boundaries(const Mesh& input, const std::vector<Index>& faces, const Topology& topology) {
  ChartBoundaries charts;
  charts.on_edge = boundary_flags(input, faces, topology);
  for (Index e = 0; e < topology.num_edges(); ++e)
    if (charts.on_edge[static_cast<std::size_t>(e)])
      charts.edges.push_back({topology.edges(e, 0), topology.edges(e, 1)});
  return charts;
}

MeshAttributes transport_attributes(const Mesh& input, const std::vector<Index>& faces, const Topology& topology,
                                    const ChartBoundaries& charts, const Vertices& moved, const Faces& output_F,
                                    TransportReport& report) {
  MeshAttributes out = input.attributes;
  const Index n = input.num_vertices();
  if (input.attributes.empty()) return out;
  const std::vector<char>& flag = charts.on_edge;
  std::vector<Index> movers;
  for (Index v = 0; v < n; ++v)
    if (moved.row(v) != input.V.row(v)) movers.push_back(v);
  report.vertices_moved = static_cast<Index>(movers.size());

  bool any_interpolated = false;
  for (const AttributeChannel& c : input.attributes.vertex) any_interpolated |= interpolated(c);
  for (const CornerChannel& c : input.attributes.corner) any_interpolated |= interpolated(c.channel);

  // Each mover's wedges and where each lands, in parallel (each vertex writes its own slots).
  std::vector<std::vector<std::vector<Index>>> wedges(movers.size());
  std::vector<std::vector<Location>> located(movers.size());
  const double h = any_interpolated ? mean_edge_length(input.V, topology) : 0;
  if (any_interpolated) {
    // Within a tenth of an edge of the best face so far: the flow's vertices are on the surface
    // (best about 0), so this is the landing point's neighbourhood, not a disk of faces (two
    // edges cost 4x the time for the same answers on the swim tests).
    const double slack = 0.1 * h;
    tbb::enumerable_thread_specific<Walker> walkers([&] { return Walker(input, faces, topology, flag, slack); });
    tbb::parallel_for(std::size_t{0}, movers.size(), [&](std::size_t i) {
      Walker& walker = walkers.local();
      wedges[i] = wedges_of(movers[i], topology, flag);
      for (const auto& wedge : wedges[i]) located[i].push_back(walker.locate(moved.row(movers[i]).transpose(), wedge));
    });
    for (const auto& locations : located)
      for (const Location& l : locations) {
        ++report.wedges_located;
        if (h > 0 && l.face >= 0) report.max_location_distance = std::max(report.max_location_distance, l.distance / h);
      }
  }
  auto corner_rows_of = [&](const Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>& corners, Index f) {
    const Index face = faces[static_cast<std::size_t>(f)];
    return std::array<Eigen::Index, 3>{corners(face, 0), corners(face, 1), corners(face, 2)};
  };

  // Vertex channels: at the first wedge's location.
  for (std::size_t c = 0; c < out.vertex.size(); ++c) {
    const AttributeChannel& in = input.attributes.vertex[c];
    if (!interpolated(in) || in.rows() != n) continue;
    for (std::size_t i = 0; i < movers.size(); ++i) {
      if (located[i].empty() || located[i].front().face < 0) continue;
      const Location& l = located[i].front();
      const Index face = faces[static_cast<std::size_t>(l.face)];
      out.vertex[c].values.row(movers[i]) =
          blend(in, {input.F(face, 0), input.F(face, 1), input.F(face, 2)}, l.barycentric);
    }
  }
  // Corner channels: each wedge in its own chart. A row used by this vertex's wedge alone is
  // rewritten; a row shared with other vertices gets a copy for this wedge.
  for (std::size_t c = 0; c < out.corner.size(); ++c) {
    const CornerChannel& in = input.attributes.corner[c];
    if (!interpolated(in.channel)) continue;
    CornerChannel& result = out.corner[c];
    std::vector<Index> row_vertex(static_cast<std::size_t>(in.channel.rows()), -1);  // -2: shared
    for (const Index face : faces)
      for (int k = 0; k < 3; ++k) {
        const std::int32_t r = in.corners(face, k);
        if (r < 0) continue;
        Index& owner = row_vertex[static_cast<std::size_t>(r)];
        owner = owner == -1 || owner == input.F(face, k) ? input.F(face, k) : -2;
      }
    std::vector<Eigen::RowVectorXd> appended;
    std::vector<char> written(static_cast<std::size_t>(in.channel.rows()), 0);
    for (std::size_t i = 0; i < movers.size(); ++i) {
      const Index v = movers[i];
      for (std::size_t w = 0; w < wedges[i].size(); ++w) {
        const Location& l = located[i][w];
        if (l.face < 0) continue;
        const std::array<Eigen::Index, 3> rows = corner_rows_of(in.corners, l.face);
        if (std::any_of(rows.begin(), rows.end(), [](Eigen::Index r) { return r < 0; })) continue;
        const Eigen::RowVectorXd value = blend(in.channel, rows, l.barycentric);
        std::int32_t own = -1;
        bool shared = false;
        for (const Index f : wedges[i][w]) {
          const Index face = faces[static_cast<std::size_t>(f)];
          const std::int32_t r = in.corners(face, corner_at(input.F, face, v));
          if (r < 0) continue;
          if (own >= 0 && r != own) shared = true;
          own = r;
          shared |= row_vertex[static_cast<std::size_t>(r)] == -2 || written[static_cast<std::size_t>(r)];
        }
        if (own < 0) continue;
        if (!shared) {
          result.channel.values.row(own) = value;
          written[static_cast<std::size_t>(own)] = 1;
          continue;
        }
        const auto row = static_cast<std::int32_t>(in.channel.rows() + static_cast<Eigen::Index>(appended.size()));
        appended.push_back(value);
        ++report.rows_added;
        for (const Index f : wedges[i][w]) {
          const Index face = faces[static_cast<std::size_t>(f)];
          const int k = corner_at(input.F, face, v);
          if (in.corners(face, k) >= 0) result.corners(face, k) = row;
        }
      }
    }
    if (!appended.empty()) {
      const Eigen::Index old_rows = result.channel.rows();
      result.channel.values.conservativeResize(old_rows + static_cast<Eigen::Index>(appended.size()), Eigen::NoChange);
      for (std::size_t a = 0; a < appended.size(); ++a)
        result.channel.values.row(old_rows + static_cast<Eigen::Index>(a)) = appended[a];
    }
  }

  // Faces changed by edge flips take, at each corner, the row their vertex has on their side of
  // any chart boundary around it: from the first face around the vertex that is unchanged or
  // holds a chart-boundary half-edge (mesh/fan_walk.h; boundaries are never flipped).
  std::vector<char> face_changed(static_cast<std::size_t>(output_F.rows()), 0);
  std::vector<Index> flipped;
  for (Index f = 0; f < output_F.rows(); ++f) {
    bool changed = output_F.row(f) != input.F.row(f);
    if (changed) flipped.push_back(f);
    for (int k = 0; k < 3; ++k) changed |= moved.row(output_F(f, k)) != input.V.row(output_F(f, k));
    face_changed[static_cast<std::size_t>(f)] = changed;
  }
  if (!flipped.empty() && !out.corner.empty()) {
    std::vector<char> at(static_cast<std::size_t>(n), 0);
    for (const Index f : flipped)
      for (int k = 0; k < 3; ++k) at[static_cast<std::size_t>(output_F(f, k))] = 1;
    const HalfEdgeFaces around(output_F, at);
    std::unordered_map<std::uint64_t, Index> boundary_face;  // directed chart-boundary half-edge -> input face
    for (Index lf = 0; lf < topology.num_faces; ++lf)
      for (int k = 0; k < 3; ++k)
        if (flag[static_cast<std::size_t>(topology.face_edges(lf, k))]) {
          const Index face = faces[static_cast<std::size_t>(lf)];
          boundary_face[half_edge_key(input.F(face, k), input.F(face, (k + 1) % 3))] = face;
        }
    auto on_boundary = [&](Index a, Index b) {
      return boundary_face.count(half_edge_key(a, b)) + boundary_face.count(half_edge_key(b, a)) > 0;
    };
    // Per flipped corner: the old face whose row it takes.
    std::vector<std::array<Index, 3>> source(flipped.size());
    for (std::size_t i = 0; i < flipped.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const Index f = flipped[i], x = output_F(f, k);
        source[i][static_cast<std::size_t>(k)] = around.walk_around(
            f, x,
            [&](Index g, Index next, Index prev) -> Index {
              if (output_F.row(g) == input.F.row(g)) return g;
              if (const auto it = boundary_face.find(half_edge_key(x, next)); it != boundary_face.end())
                return it->second;
              if (const auto it = boundary_face.find(half_edge_key(prev, x)); it != boundary_face.end())
                return it->second;
              return -1;
            },
            [&](Index a, Index b) { return !on_boundary(a, b); });
        // No boundary and no unchanged face around x: x is in one chart, any old face serves.
        const auto first = static_cast<std::size_t>(topology.face_offsets[static_cast<std::size_t>(x)]);
        if (source[i][static_cast<std::size_t>(k)] < 0 &&
            first < static_cast<std::size_t>(topology.face_offsets[static_cast<std::size_t>(x) + 1]))
          source[i][static_cast<std::size_t>(k)] = faces[static_cast<std::size_t>(topology.vertex_faces[first])];
      }
    for (CornerChannel& c : out.corner) {
      const auto old_corners = c.corners;  // the rows of the faces as they were
      for (std::size_t i = 0; i < flipped.size(); ++i)
        for (int k = 0; k < 3; ++k) {
          const Index f = flipped[i], x = output_F(f, k), g = source[i][static_cast<std::size_t>(k)];
          const int corner = g >= 0 ? corner_at(input.F, g, x) : -1;
          c.corners(f, k) = corner >= 0 ? old_corners(g, corner) : -1;
        }
    }
  }

  // Normals from the moved geometry, the input's split kept.
  for (AttributeChannel& c : out.vertex)
    if (c.role == AttributeRole::Normal && c.width() >= 3 && c.rows() == n) {
      recompute_normals(c, nullptr, moved, output_F, face_changed);
      ++report.normal_channels;
    }
  for (CornerChannel& c : out.corner)
    if (c.channel.role == AttributeRole::Normal && c.channel.width() >= 3) {
      recompute_normals(c.channel, &c.corners, moved, output_F, face_changed);
      ++report.normal_channels;
    }
  return out;
}

}  // namespace vertexflow::attributes_detail
