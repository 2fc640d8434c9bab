// The sparse structure of a topology and the KLU solver that factors with it: the solver solves
// the Newton systems it is given (fresh factorization, refactorization with the old pivots, new
// pivots when the old ones went bad, a singular matrix as a recoverable failure); the cache hands
// one structure to every model of a topology and a new one to each other topology; a run with a
// shared structure is the run without one, bit for bit. The modal analysis's fill-reducing
// ordering is SimplicialLDLT's own and is cached by topology too.
#include "core/analysis/sparse_structure.hpp"

#include <gtest/gtest.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <random>
#include <string>
#include <thread>

#include "core/analysis/klu_solver.hpp"
#include "core/analysis/sundials_support.hpp"
#include "core/model/forces.hpp"
#include "core/model/generalized.hpp"
#include "tests/support/reference_cantilever.hpp"
#include "tests/support/transient_run.hpp"

namespace beamrail {
namespace {

using testing::scene_from_json;

using testing::reference_cantilever;

// Bodies b1 and b2, b1 held by ground and b2 by `holder`.
std::string two_bodies(const std::string& holder) {
  return R"({"materials": {"steel": {"E": 2.1e11, "G": 8.0769e10, "density": 7850}},
    "sections": {"sq": {"shape": "rectangle", "width": 0.01, "height": 0.01}},
    "bodies": [{"name": "b1", "mass": 1, "inertia": [1e-3, 1e-3, 1e-3], "position": [1, 0, 0]},
               {"name": "b2", "mass": 1, "inertia": [1e-3, 1e-3, 1e-3], "position": [2, 0, 0]}],
    "beams": [{"name": "one", "body1": "ground", "body2": "b1", "point1": [0, 0, 0],
               "point2": [1, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"},
              {"name": "two", "body1": ")" +
         holder + R"(", "body2": "b2", "point1": [1, 0, 0],
               "point2": [2, 0, 0], "point3": [0, 1, 0], "material": "steel", "section": "sq"}]})";
}

// A SUNDIALS CSC matrix holding the structure's pattern, its values drawn by `value(row, col)`.
template <class F>
void fill(const SparseStructure& s, SUNMatrix a, F&& value) {
  const JacobianPattern& p = s.pattern();
  sunindextype* starts = SUNSparseMatrix_IndexPointers(a);
  sunindextype* rows = SUNSparseMatrix_IndexValues(a);
  double* values = SUNSparseMatrix_Data(a);
  for (long j = 0; j <= s.n(); ++j) starts[j] = p.column_starts[j];
  for (long j = 0; j < s.n(); ++j)
    for (long k = p.column_starts[j]; k < p.column_starts[j + 1]; ++k) {
      rows[k] = p.rows[k];
      values[k] = value(p.rows[k], j);
    }
}

Eigen::MatrixXd dense(const SparseStructure& s, SUNMatrix a) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(s.n(), s.n());
  const JacobianPattern& p = s.pattern();
  const double* values = SUNSparseMatrix_Data(a);
  for (long j = 0; j < s.n(); ++j)
    for (long k = p.column_starts[j]; k < p.column_starts[j + 1]; ++k) m(p.rows[k], j) = values[k];
  return m;
}

// Solves A x = b with the KLU solver; returns |A x - b| / (|A| |x|), or -1 when setup failed.
double solve_residual(SUNLinearSolver solver, const SparseStructure& s, SUNMatrix a, SUNContext ctx,
                      std::mt19937& rng) {
  if (SUNLinSolSetup(solver, a) != SUNLS_SUCCESS) return -1.0;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SerialVector b(s.n(), ctx), x(s.n(), ctx);
  for (long i = 0; i < s.n(); ++i) b.data()[i] = u(rng);
  EXPECT_EQ(SUNLinSolSolve(solver, a, x, b, 0.0), SUNLS_SUCCESS);
  const Eigen::MatrixXd m = dense(s, a);
  const Eigen::Map<const Eigen::VectorXd> xv(x.data(), s.n()), bv(b.data(), s.n());
  return (m * xv - bv).norm() / (m.norm() * xv.norm());
}

TEST(KluSolver, SolvesFactorsRefactorsRepivotsAndReportsSingularMatrices) {
  const Model model = scene_from_json(reference_cantilever(6));
  const SparseStructure s(model);
  ASSERT_EQ(s.n(), 78);
  SundialsContext ctx;
  MatrixOwner a;
  a.m = SUNSparseMatrix(s.n(), s.n(), s.pattern().nnz(), CSC_MAT, ctx);
  LinearSolverOwner solver;
  solver.s = make_klu_solver(std::shared_ptr<const SparseStructure>(&s, [](auto*) {}), ctx);
  ASSERT_TRUE(solver.s);
  ASSERT_EQ(SUNLinSolInitialize(solver.s), SUNLS_SUCCESS);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);

  // Newton matrices I - gamma J of the equations of motion: position rows as the kinematics make
  // them (dc/dt = v: 1 on the diagonal, -gamma in the velocity column; dq/dt: I - gamma dq'/dq
  // and a 4 x 3 block in the w columns, scaled by gamma), velocity rows drawn by
  // `velocity_rows(row, col)`.
  const auto newton = [&](auto&& velocity_rows, double gamma = 1e-3) {
    return [&, velocity_rows, gamma](long r, long col) {
      const long lr = r % kStatesPerBody, lc = col % kStatesPerBody;
      if (lr >= kPositionStates) return velocity_rows(r, col);
      if (lr < 3) return lc == lr ? 1.0 : -gamma;
      if (lc < kPositionStates) return (lc == lr ? 1.0 : 0.0) + gamma * u(rng);
      return gamma * u(rng);
    };
  };
  // Strong diagonal. The first setup factors with pivoting.
  fill(s, a.m, newton([&](long r, long c) { return (r == c ? 10.0 : 0.0) + u(rng); }));
  const double first = solve_residual(solver.s, s, a.m, ctx, rng);
  // New values of the same pattern: refactored with the first pivots.
  fill(s, a.m, newton([&](long r, long c) { return (r == c ? 5.0 : 0.0) + u(rng); }));
  const double refactored = solve_residual(solver.s, s, a.m, ctx, rng);
  // Values for which the first pivot order is nearly singular (a tiny diagonal): the solver must
  // notice the poor pivots and factor afresh, or the residual would grow by the pivot growth.
  // (gamma 0: the velocity-level matrix is then the velocity block itself, tiny diagonal and all.)
  fill(s, a.m, newton([&](long r, long c) { return r == c ? 1e-13 : u(rng); }, 0.0));
  const double repivoted = solve_residual(solver.s, s, a.m, ctx, rng);
  std::printf("relative residuals: factor %.2e, refactor %.2e, new pivots %.2e\n", first,
              refactored, repivoted);
  EXPECT_GE(first, 0.0);
  EXPECT_LT(first, 1e-14);
  EXPECT_GE(refactored, 0.0);
  EXPECT_LT(refactored, 1e-14);
  EXPECT_GE(repivoted, 0.0);
  EXPECT_LT(repivoted, 1e-12);

  // A zero column (body 1's v_x): a singular Newton matrix is a recoverable failure (the integrator
  // retries with a smaller step), before and after a successful factorization.
  const auto regular = newton([&](long r, long c) { return (r == c ? 10.0 : 0.0) + u(rng); });
  fill(s, a.m, [&](long r, long c) { return c == 20 ? 0.0 : regular(r, c); });
  EXPECT_EQ(SUNLinSolSetup(solver.s, a.m), SUNLS_PACKAGE_FAIL_REC);
  EXPECT_EQ(SUNLinSolLastFlag(solver.s), SUNLS_PACKAGE_FAIL_REC);
  fill(s, a.m, newton([&](long r, long c) { return (r == c ? 10.0 : 0.0) + u(rng); }));
  const double recovered = solve_residual(solver.s, s, a.m, ctx, rng);
  EXPECT_GE(recovered, 0.0);
  EXPECT_LT(recovered, 1e-14);

  // A matrix of another size is refused, not read out of bounds.
  MatrixOwner other;
  other.m = SUNSparseMatrix(13, 13, 13, CSC_MAT, ctx);
  EXPECT_EQ(SUNLinSolSetup(solver.s, other.m), SUNLS_ILL_INPUT);
}

TEST(SparseStructureCache, OneStructurePerTopology) {
  SparseStructureCache cache;
  // Same topology, other section and length: the same structure.
  const Model a = scene_from_json(reference_cantilever(6));
  const Model b = scene_from_json(reference_cantilever(6, 0.02, 2.5));
  const auto sa = cache.get(a);
  const auto sb = cache.get(b);
  EXPECT_EQ(sa.get(), sb.get());
  EXPECT_EQ(cache.analyses(), 1);
  EXPECT_EQ(cache.reuses(), 1);
  // Another segment count: another structure, and the first one is still there.
  const Model c = scene_from_json(reference_cantilever(7));
  const auto sc = cache.get(c);
  EXPECT_NE(sc.get(), sa.get());
  EXPECT_EQ(sc->n(), 91);
  EXPECT_EQ(cache.get(a).get(), sa.get());
  EXPECT_EQ(cache.analyses(), 2);
  EXPECT_EQ(cache.reuses(), 2);
  // Same state count, other couplings: two bodies in a chain (ground - b1 - b2) and the same two
  // bodies each held by ground (no coupling between them).
  const Model chain = scene_from_json(two_bodies("b1"));
  const Model separate = scene_from_json(two_bodies("ground"));
  ASSERT_EQ(chain.n_states, separate.n_states);
  const auto s_chain = cache.get(chain);
  const auto s_separate = cache.get(separate);
  EXPECT_NE(s_chain.get(), s_separate.get());
  EXPECT_GT(s_chain->pattern().nnz(), s_separate->pattern().nnz());
  EXPECT_EQ(cache.analyses(), 4);
  // More topologies than the cache keeps: the least recently used is analysed again.
  for (int n = 8; n < 8 + 8; ++n) cache.get(scene_from_json(reference_cantilever(n)));
  const long before = cache.analyses();
  cache.get(a);
  EXPECT_EQ(cache.analyses(), before + 1);
}

// The ordering symmetric_ordering reads off a pattern is the one Eigen's SimplicialLDLT chooses
// for the matrix itself (so a factorization with the shared ordering is SimplicialLDLT's), and
// it reads the pattern only: other values, even zeros stored, give the same permutation.
TEST(SymmetricOrdering, IsSimplicialLdltsOwnAndReadsThePatternOnly) {
  const Model model = scene_from_json(reference_cantilever(40));
  Data data(model);
  compute_tangent(model, data, 0.0, false);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(model.n_dofs);
  const Eigen::SparseMatrix<double> k = symmetric_stiffness(model, data, ones, nullptr);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const SymmetricOrdering p = symmetric_ordering(k);
  ASSERT_EQ(p.size(), k.rows());
  EXPECT_EQ(p.indices(), ldlt.permutationP().indices());
  // Not the chain's own order (else the comparison would show little).
  EXPECT_NE(p.indices(), SymmetricOrdering(k.rows()).indices());
  Eigen::SparseMatrix<double> other = k;
  for (Eigen::Index i = 0; i < other.nonZeros(); ++i)
    other.valuePtr()[i] = i % 3 == 0 ? 0.0 : std::sin(static_cast<double>(i));
  EXPECT_EQ(symmetric_ordering(other).indices(), p.indices());
}

// The modal analysis's ordering is cached by topology like the structure, without making one (a
// modal analysis needs neither the Jacobian's pattern nor KLU's analysis), and a structure made
// later for the topology keeps it.
TEST(SparseStructureCache, OneOrderingPerTopology) {
  SparseStructureCache cache;
  const auto stiffness = [](const Model& m) {
    Data data(m);
    compute_tangent(m, data, 0.0, false);
    return symmetric_stiffness(m, data, Eigen::VectorXd::Ones(m.n_dofs), nullptr);
  };
  const Model a = scene_from_json(reference_cantilever(6));
  const Model b = scene_from_json(reference_cantilever(6, 0.02, 2.5));
  const auto pa = cache.ordering(a, stiffness(a));
  const auto pb = cache.ordering(b, stiffness(b));
  EXPECT_EQ(pa.get(), pb.get());
  EXPECT_EQ(cache.orderings(), 1);
  EXPECT_EQ(cache.ordering_reuses(), 1);
  EXPECT_EQ(cache.analyses(), 0);
  EXPECT_EQ(pa->indices(), symmetric_ordering(stiffness(b)).indices());
  const auto sa = cache.get(a);
  EXPECT_EQ(cache.analyses(), 1);
  EXPECT_EQ(cache.ordering(b, stiffness(b)).get(), pa.get());
  EXPECT_EQ(cache.get(b).get(), sa.get());
  EXPECT_EQ(cache.orderings(), 1);
  EXPECT_EQ(cache.ordering_reuses(), 2);
  const Model c = scene_from_json(reference_cantilever(7));
  EXPECT_NE(cache.ordering(c, stiffness(c)).get(), pa.get());
  EXPECT_EQ(cache.orderings(), 2);
  // Threads meeting a new topology at once all get the one ordering kept.
  const Model d = scene_from_json(reference_cantilever(9));
  const Eigen::SparseMatrix<double> kd = stiffness(d);
  std::vector<std::shared_ptr<const SymmetricOrdering>> got(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < got.size(); ++t)
    threads.emplace_back([&, t] { got[t] = cache.ordering(d, kd); });
  for (auto& t : threads) t.join();
  for (const auto& p : got) EXPECT_EQ(p.get(), got[0].get());
}

TEST(SparseStructureCache, ARunWithASharedStructureIsTheRunWithout) {
  const Model model = scene_from_json(reference_cantilever(6));
  TransientOptions o = testing::options(0.02, 1e-3, 1e-7, 1e-10);
  o.integrator.linear_solver = LinearSolverKind::kSparse;
  o.integrator.method = IntegratorMethod::kDirk;
  const testing::TransientRun alone = testing::simulate(model, o);
  SparseStructureCache cache;
  o.structure_cache = &cache;
  const Model other = scene_from_json(reference_cantilever(6, 0.012, 1.1));
  ASSERT_TRUE(testing::simulate(other, o).result.ok);  // analyses the topology
  const testing::TransientRun shared = testing::simulate(model, o);
  EXPECT_EQ(cache.analyses(), 1);
  EXPECT_EQ(cache.reuses(), 1);
  ASSERT_TRUE(alone.result.ok && shared.result.ok);
  ASSERT_EQ(alone.samples.size(), shared.samples.size());
  EXPECT_EQ(alone.result.stats.steps, shared.result.stats.steps);
  for (size_t k = 0; k < alone.samples.size(); ++k)
    for (size_t b = 0; b < model.bodies.size(); ++b) {
      EXPECT_EQ(alone.samples[k].c[b], shared.samples[k].c[b]);
      EXPECT_EQ(alone.samples[k].q[b], shared.samples[k].q[b]);
    }
}

}  // namespace
}  // namespace beamrail
