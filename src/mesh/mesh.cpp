#include "vertexflow/mesh.h"

#include <Eigen/Geometry>

#include <stdexcept>

namespace vertexflow {

BoundingBox bounding_box(const Vertices& V) {
  BoundingBox box;
  if (V.rows() == 0) return box;
  box.min = V.colwise().minCoeff().transpose();
  box.max = V.colwise().maxCoeff().transpose();
  return box;
}

Eigen::Vector3d face_normal(const Vertices& V, const Faces& F, Index f) {
  const Eigen::Vector3d a = V.row(F(f, 0));
  const Eigen::Vector3d b = V.row(F(f, 1));
  const Eigen::Vector3d c = V.row(F(f, 2));
  return (b - a).cross(c - a);
}

double face_area(const Vertices& V, const Faces& F, Index f) {
  return 0.5 * face_normal(V, F, f).norm();
}

double signed_volume(const Vertices& V, const Faces& F) {
  double volume = 0;
  for (Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    volume += a.dot(b.cross(c));
  }
  return volume / 6.0;
}

std::vector<Index> flipped_faces(const Vertices& before, const Vertices& after, const Faces& F) {
  std::vector<Index> out;
  for (Index f = 0; f < F.rows(); ++f) {
    if (face_normal(before, F, f).dot(face_normal(after, F, f)) < 0) out.push_back(f);
  }
  return out;
}

std::vector<Index> degenerate_faces(const Vertices& V, const Faces& F) {
  const double min_area = degenerate_area_bound(bounding_box(V).diagonal());
  std::vector<Index> out;
  for (Index f = 0; f < F.rows(); ++f) {
    if (0.5 * face_normal(V, F, f).norm() < min_area) out.push_back(f);
  }
  return out;
}

}  // namespace vertexflow
