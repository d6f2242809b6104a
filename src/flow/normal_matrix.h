// Internal to the flow stage: H of flow_terms.h assembled over the free vertices, for the
// direct factorisation (LinearSolver::Direct).
#pragma once

#include "flow_terms.h"
#include "numerics/sparse_cholesky.h"

#include <cstdint>
#include <vector>

namespace vertexflow {

/// The free vertices of FlowTerms and the pattern of H's 3x3 blocks over them: two free
/// vertices are coupled when some star contains both (a two-ring). Depends only on the
/// connectivity and the fixed vertices, so it is built once per solver.
struct NormalMatrixPattern {
  std::vector<Index> free_index;   ///< local index -> free index, -1 for fixed vertices
  std::vector<Index> free_vertex;  ///< free index -> local index
  /// Lower half by rows (= upper half by columns): row a holds the free indices b <= a.
  std::vector<std::int64_t> row_start;
  std::vector<Index> row_columns;
};

/// The free vertices' numbering, in local order, and the pattern.
NormalMatrixPattern normal_matrix_pattern(const FlowTerms& terms);

/// H over the free vertices with its 3x3 blocks expanded, upper half by columns: column 3a + r
/// holds rows 3b + c for b < a, and b = a with c <= r. Each block is the sum over the stars
/// holding both vertices of G_iu P_i G_iw + S_i L_iu L_iw I, plus D_u on the diagonal.
SparseCholesky::UpperMatrix assemble_normal_matrix(const FlowTerms& terms, const NormalMatrixPattern& pattern,
                                                   SparseCholesky& cholesky);

}  // namespace vertexflow
