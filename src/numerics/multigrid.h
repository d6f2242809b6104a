// Internal: an additive multilevel preconditioner built by smoothed aggregation, for symmetric
// positive definite matrices of 3x3 blocks (x, y, z of one node). The flow uses it on the
// coarse problem of LinearSolver::Multilevel (aggregation_coarse_space.h).
//
// Written here because no Debian package offers algebraic multigrid outside MPI stacks
// (hypre, PETSc, Trilinos), and AMGCL, the header-only reference for the method, is not
// packaged. The hierarchy is Vanek, Mandel and Brezina's smoothed aggregation (Computing 56,
// 1996): aggregates of strongly coupled nodes, the three translations as near null space, the
// tentative prolongator smoothed by one damped block-Jacobi step and truncated
// (smoothed_prolongator), Galerkin coarse matrices and a dense Cholesky factorisation on the
// coarsest level. The levels are combined additively
// (BPX style, block-Jacobi on each level) rather than in a V-cycle: measured on fandisk's
// coarse problem, a Gauss-Seidel V-cycle took 20% fewer outer iterations but each cost 1.5x
// more, since its sweeps are sequential. The matrices are kept as 3x3 blocks throughout (not
// Eigen's scalar sparse products, which took 4x longer to build the same hierarchy).
#pragma once

#include <Eigen/Dense>

#include <functional>
#include <utility>
#include <vector>

namespace vertexflow {

/// A sparse matrix of 3x3 blocks in compressed rows: row k holds the blocks (k, column[m]) for
/// m in [start[k], start[k+1]), columns increasing. Blocks of double (BlockSparseMatrix), or
/// of float for matrices that are only applied (FloatBlockSparseMatrix).
template <class Scalar>
struct BasicBlockSparseMatrix {
  int rows = 0, cols = 0;  // in blocks
  std::vector<int> start{0};
  std::vector<int> column;
  std::vector<Eigen::Matrix<Scalar, 3, 3>> block;

  /// y = A x (3 entries per block row / column), in double whatever the blocks' type.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
};
using BlockSparseMatrix = BasicBlockSparseMatrix<double>;
/// Half the bytes of a BlockSparseMatrix: the multilevel operator's prolongations and
/// restrictions, read at every application and kept through the whole iteration.
using FloatBlockSparseMatrix = BasicBlockSparseMatrix<float>;

/// A's blocks rounded to float.
FloatBlockSparseMatrix rounded_to_float(const BlockSparseMatrix& A);

/// The blocks of one row under construction, keyed by column (a sparse accumulator):
/// row[column] is the block, zero when first touched.
class BlockRowAccumulator {
 public:
  explicit BlockRowAccumulator(int cols);
  Eigen::Matrix3d& operator[](int column);
  /// Appends the row's blocks, sorted by column, to `column` and `block`, clears the
  /// accumulator (keeping its storage for the next row) and returns how many it appended.
  int append_to(std::vector<int>& column, std::vector<Eigen::Matrix3d>& block);

 private:
  std::vector<int> position_;
  std::vector<std::pair<int, Eigen::Matrix3d>> entries_;
};

/// A rows x cols block matrix whose row k is what body(k, row) adds to `row`. Rows are built
/// in parallel, each row's blocks summed in the order body adds them, so the result does not
/// depend on the threads. They are built `range_rows` at a time, and `prepare(first, last)`, when
/// given, runs before the rows [first, last) are: what body reads for those rows only.
BlockSparseMatrix build_block_rows(int rows, int cols, const std::function<void(int, BlockRowAccumulator&)>& body,
                                   int range_rows = 8192, const std::function<void(int, int)>& prepare = {});

/// The symmetric matrix whose upper half (diagonal included) is `upper`'s; `upper` must hold
/// no block below the diagonal.
BlockSparseMatrix symmetric_from_upper(const BlockSparseMatrix& upper);

/// Greedy aggregation of a graph (Vanek et al.'s three phases): a node whose neighbours are all
/// free of aggregates starts one with them; the remaining nodes join the aggregate of a
/// nearest aggregated node (breadth first); nodes that still have none start aggregates of
/// their connected remainder. `excluded` nodes get -1. Deterministic: nodes are visited in
/// index order. The graph is CSR: node k's neighbours are neighbours[start[k] .. start[k+1]).
/// Returns the aggregate of every node; `count` receives the number of aggregates.
std::vector<int> aggregate_nodes(const std::vector<int>& start, const std::vector<int>& neighbours,
                                 const std::vector<char>& excluded, int& count);

/// The smoothed-aggregation prolongator from A's nodes to `count` aggregates (aggregate[k] of
/// node k, as aggregate_nodes gives): P = (I - omega B A) P_t, with P_t the translations of each
/// aggregate (block I / sqrt(|a|) on its nodes, so that its columns have unit length) and B =
/// `block_inverse`, A's inverse diagonal blocks. Then, in each row, every block but the own
/// aggregate's whose Frobenius norm is below `truncation` times the row's largest is dropped
/// and lumped into the own aggregate's block, scaled so that P still maps each coarse
/// translation (c_a = sqrt(|a|) t, which P_t maps to t on every node) to (I - omega B A) t:
/// narrower rows, the same near null space. `truncation` 0 keeps every block; `omega` 0 gives
/// P_t. Deterministic.
BlockSparseMatrix smoothed_prolongator(const BlockSparseMatrix& A, const std::vector<int>& aggregate, int count,
                                       const std::vector<Eigen::Matrix3d>& block_inverse, double omega,
                                       double truncation);

/// The additive multilevel operator M = B_0 + P_1 (B_1 + P_2 (... + A_L^-1 ...) P_2^T) P_1^T,
/// with B_l the inverses of level l's 3x3 diagonal blocks and A_L the coarsest Galerkin matrix,
/// factored densely; where coarsening stalls on a level of more than max(coarsest_unknowns,
/// 1,500) unknowns (its nodes mostly without strong neighbours, as when a mesh has thousands of
/// separate components), A_L^-1 is replaced by A_L's block-Jacobi inverse, so that memory and
/// time stay linear. M is symmetric positive definite, so it can precondition conjugate
/// gradients. Deterministic, and the same for any thread count.
class AdditiveMultilevel {
 public:
  /// How the matrix given to the constructor is stored.
  enum class Storage {
    Whole,      ///< both halves
    UpperHalf,  ///< its upper half, diagonal included, and no block below the diagonal
  };

  /// The default most unknowns of the coarsest level (factored densely).
  static constexpr int kCoarsestUnknowns = 240;

  /// The prolongators between levels.
  enum class Prolongators {
    /// Smoothed by one damped block-Jacobi step and truncated (smoothed_prolongator): wider
    /// rows, fewer iterations on scalar grid operators, second order or bi-Laplacian (the
    /// tests' grids: a Laplacian 36 against 148 iterations, a bi-Laplacian 478 against 919).
    Smoothed,
    /// The tentative ones, the translations of each aggregate (one block per row): a sparser
    /// hierarchy, cheaper to build and apply. On the flow's coarse problems of curved surfaces,
    /// whose blocks are stiff along normals that turn from node to node, they also took fewer
    /// iterations (docs/benchmarks.md, "Tentative prolongators off planar regions"): the 10M
    /// armadillo 72 -> 64 and its set-up 15.7 -> 11.6 s, amo 48 -> 37; on planar regions, where
    /// the problem is a bi-Laplacian, more (a chamfered cube split to 141k vertices 114 -> 255).
    Tentative,
  };

  /// A: symmetric positive definite, stored as `storage` says (the upper half saves the lower
  /// half's copy, the set-up's largest matrix; the hierarchy is the same bytes either way).
  /// Coarsens until at most `coarsest_unknowns` unknowns remain or coarsening stalls. Throws
  /// std::runtime_error if the coarsest matrix is not numerically positive definite.
  explicit AdditiveMultilevel(BlockSparseMatrix A, Storage storage = Storage::Whole,
                              int coarsest_unknowns = kCoarsestUnknowns,
                              Prolongators prolongators = Prolongators::Smoothed);

  /// x = M b.
  void apply(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;

  [[nodiscard]] int num_levels() const { return static_cast<int>(levels_.size()) + 1; }
  [[nodiscard]] Eigen::Index coarsest_unknowns() const { return coarsest_unknowns_; }
  /// Whether the coarsest level is factored (else it has its block-Jacobi inverse).
  [[nodiscard]] bool coarsest_factored() const { return coarsest_block_inverse_.empty(); }

 private:
  // P and R in float: a preconditioner needs only to be symmetric positive definite, which
  // R = P^T of the same rounded blocks keeps; they were most of the hierarchy's bytes.
  struct Level {
    std::vector<Eigen::Matrix3d> block_inverse;  // B_l
    FloatBlockSparseMatrix P;                    // prolongation from the next level
    FloatBlockSparseMatrix R;                    // P^T
  };
  void apply(std::size_t level, const Eigen::VectorXd& b, Eigen::VectorXd& x) const;

  std::vector<Level> levels_;
  Eigen::Index coarsest_unknowns_ = 0;
  Eigen::LLT<Eigen::MatrixXd> coarsest_factor_;
  std::vector<Eigen::Matrix3d> coarsest_block_inverse_;  // instead of the factor, on a stalled large level
};

}  // namespace vertexflow
