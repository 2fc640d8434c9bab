#include "core/analysis/modal_band.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <utility>

#include "core/analysis/element_deformation.hpp"
#include "core/analysis/modal_analysis.hpp"
#include "core/analysis/modal_integrator.hpp"

namespace beamrail {
namespace {

constexpr int kD = kDofsPerBody;

bool same_function(const TimeFunction& a, const TimeFunction& b) {
  return a.type == b.type && a.at == b.at && a.from == b.from && a.to == b.to &&
         a.frequency == b.frequency && a.phase == b.phase && a.t == b.t && a.v == b.v;
}

// How a load's time function changes after t0 and before t1: false when it does not; else *rate
// (0 for a jump) and *factor (its largest value). A jump at t1 (the run's end) acts after it.
bool change_after(const TimeFunction& f, double t0, double t1, double* rate, double* factor) {
  *factor = 1.0;
  switch (f.type) {
    case TimeFunction::Type::kConstant:
      return false;
    case TimeFunction::Type::kStep:
      *rate = 0.0;
      return f.at > t0 && f.at < t1;  // a step at t0 is in the force out of balance there
    case TimeFunction::Type::kRamp: {
      if (f.to <= t0 || f.from >= t1) return false;
      // Its kinks within the run (at least one: a run that starts on the ramp starts at rest).
      const double kinks = std::max(1.0, (f.from >= t0 ? 1.0 : 0.0) + (f.to < t1 ? 1.0 : 0.0));
      *rate = f.to > f.from ? kinks / (f.to - f.from) : 0.0;
      return true;
    }
    case TimeFunction::Type::kSmoothRamp:  // one cycle of a cosine in its acceleration
      if (f.to <= t0 || f.from >= t1) return false;
      *rate = 2.0 * std::numbers::pi / (f.to - f.from);
      return true;
    case TimeFunction::Type::kHarmonic:
      *rate = 2.0 * std::numbers::pi * std::abs(f.frequency);
      return f.frequency != 0.0;
    case TimeFunction::Type::kTable: {
      // Slope changes at the knots in [t0, t1) (held outside: slope 0 before and after).
      double kinks = 0.0, previous = 0.0;
      *factor = 0.0;
      for (size_t k = 0; k < f.t.size(); ++k) {
        const double slope =
            k + 1 < f.t.size() ? (f.v[k + 1] - f.v[k]) / (f.t[k + 1] - f.t[k]) : 0.0;
        // The knots from t0 on, and the slope of the segment t0 lies in (the run starts on it).
        if (f.t[k] < t1 && (f.t[k] >= t0 || (k + 1 < f.t.size() && f.t[k + 1] > t0)))
          kinks += f.t[k] >= t0 ? std::abs(slope - previous) : std::abs(slope);
        previous = slope;
        *factor = std::max(*factor, std::abs(f.v[k]));
      }
      if (!(*factor > 0.0) || kinks == 0.0) return false;
      *rate = kinks / *factor;
      return true;
    }
  }
  return false;
}

// A load factor's changes over [0, horizon] after t0 (times from t0): its jumps and the linear
// pieces of the rest (exact for ramps and tables; a smooth ramp or a harmonic factor in at least
// 64 pieces, 16 per period).
struct FactorChanges {
  std::vector<std::pair<double, double>> jumps;  // (time, size)
  std::vector<std::array<double, 3>> pieces;     // (from, to, slope)
  double start = 0.0;                            // the first change
};

FactorChanges factor_changes(const BandExcitation& e, double horizon) {
  FactorChanges c;
  const TimeFunction* f = e.time;
  if (!f) {
    c.jumps.push_back({0.0, 1.0});
    return c;
  }
  if (f->type == TimeFunction::Type::kStep) {
    if (f->at > e.t0 && f->at < e.t0 + horizon) c.jumps.push_back({f->at - e.t0, 1.0});
    c.start = c.jumps.empty() ? horizon : c.jumps.front().first;
    return c;
  }
  std::vector<double> knots, times = {0.0, horizon};
  f->append_breakpoints(knots);
  if (f->type == TimeFunction::Type::kSmoothRamp) knots.insert(knots.end(), {f->from, f->to});
  for (double k : knots)
    if (k > e.t0 && k < e.t0 + horizon) times.push_back(k - e.t0);
  const int pieces =
      f->type == TimeFunction::Type::kHarmonic
          ? static_cast<int>(std::clamp(16.0 * std::abs(f->frequency) * horizon, 64.0, 1024.0))
          : 64;
  for (int i = 1; i < pieces; ++i) times.push_back(horizon * i / pieces);
  std::sort(times.begin(), times.end());
  c.start = horizon;
  for (size_t i = 0; i + 1 < times.size(); ++i) {
    const double a = times[i], b = times[i + 1];
    if (!(b > a)) continue;
    const double slope = ((*f)(e.t0 + b) - (*f)(e.t0 + a)) / (b - a);
    if (slope == 0.0) continue;
    c.pieces.push_back({a, b, slope});
    c.start = std::min(c.start, a);
  }
  return c;
}

// The factor's change from t0 to t0 + tau, and the response then of an undamped mode of angular
// frequency w at rest at t0 whose static response to a unit factor is 1.
double factor_change(const FactorChanges& c, double tau) {
  double x = 0.0;
  for (const auto& [time, size] : c.jumps)
    if (tau >= time) x += size;
  for (const auto& [a, b, slope] : c.pieces)
    if (tau > a) x += slope * (std::min(tau, b) - a);
  return x;
}

double mode_response(const FactorChanges& c, double w, double tau) {
  double x = 0.0;
  for (const auto& [time, size] : c.jumps)
    if (tau >= time) x += size * (1.0 - std::cos(w * (tau - time)));
  for (const auto& [a, b, slope] : c.pieces) {
    if (tau <= a) continue;
    if (tau <= b)
      x += slope * ((tau - a) - std::sin(w * (tau - a)) / w);
    else
      x += slope * ((b - a) - (std::sin(w * (tau - a)) - std::sin(w * (tau - b))) / w);
  }
  return x;
}

}  // namespace

// The times at which an early run's motion is sampled (choose_band's horizon).
constexpr int kHorizonSamples = 32;

BandChoice choose_band(const Eigen::VectorXd& lambda, const Eigen::MatrixXd& phi,
                       const Eigen::SparseMatrix<double>& m0,
                       const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& shifted, double mu,
                       const std::vector<BandExcitation>& excitations,
                       const std::vector<int>& watched, double tolerance, double horizon,
                       Eigen::Index fixed, Eigen::Index rigid_given) {
  const Eigen::Index total = lambda.size();
  BandChoice choice;
  if (total == 0) return choice;
  const double top = lambda.cwiseAbs().maxCoeff();
  // Rigid and mechanism modes (w^2 at rounding level or below) stay in the band.
  Eigen::Index rigid = 0;
  double lowest_positive = 0.0;
  for (Eigen::Index i = 0; i < total; ++i) {
    if (rigid_given >= 0 ? i < rigid_given : lambda(i) <= 1e-8 * top)
      rigid = i + 1;
    else if (lowest_positive == 0.0 && lambda(i) > 0.0)
      lowest_positive = lambda(i);
  }
  // So do the modes a harmonic load could drive near resonance (w below kBandResonanceMargin
  // times its frequency): quasi-static, they would miss the amplification.
  Eigen::Index least = std::max<Eigen::Index>(rigid, 1);
  double driven = 0.0;
  for (const BandExcitation& e : excitations)
    if (e.harmonic) driven = std::max(driven, kBandResonanceMargin * e.rate);
  while (least < total && lambda(least - 1) < driven * driven) ++least;
  if (least == total && lambda(total - 1) < driven * driven) least = total + 1;  // ask for more
  const bool complete = phi.cols() == phi.rows();  // every mode given: nothing beyond them
  const Eigen::ArrayXd w = lambda.array().max(lowest_positive > 0.0 ? lowest_positive : 1.0).sqrt();
  // The rows measured: the translations of the bodies watched, or their rotations when nothing
  // translates.
  std::vector<int> bodies = watched;
  if (bodies.empty())
    for (int b = 0; b < phi.rows() / kD; ++b) bodies.push_back(b);
  const auto rows_of = [&](int part) {
    std::vector<Eigen::Index> rows;
    for (int b : bodies)
      for (int j = 0; j < 3; ++j) rows.push_back(kD * static_cast<Eigen::Index>(b) + 3 * part + j);
    return rows;
  };
  // Per excitation: the full response and each mode's part of it, weighted by how much of it
  // rings (1 for a jump, 1 / w for a velocity, rate / w for a smooth change).
  struct Track {
    Eigen::VectorXd full;
    Eigen::ArrayXd coefficients;  // of each mode in the full response
    Eigen::ArrayXd weights;       // of each mode's ringing
    double beyond_weight = 1.0;   // of the modes above those given
  };
  std::vector<Track> tracks;
  double scale[2] = {0.0, 0.0};  // the motion's size: translations, rotations
  for (const BandExcitation& e : excitations) {
    Track t;
    if (e.kind == BandExcitation::Kind::kForce) {
      t.full = e.factor * shifted.solve(e.vector);
      t.coefficients = e.factor * (phi.transpose() * e.vector).array() / (lambda.array() + mu);
    } else {
      t.full = e.vector;
      t.coefficients = (phi.transpose() * (m0 * e.vector)).array();
    }
    // The size of the motion from the elastic response only: the rigid modes' part of a force's
    // response, F / mu, depends on the shift, not on the motion.
    Eigen::VectorXd elastic = t.full;
    for (Eigen::Index k = 0; k < rigid; ++k) elastic -= t.coefficients(k) * phi.col(k);
    const double w_last = w(total - 1);
    switch (e.kind) {
      case BandExcitation::Kind::kVelocity:
        t.weights = 1.0 / w;
        t.beyond_weight = 1.0 / w_last;
        break;
      case BandExcitation::Kind::kForce:
        t.weights =
            e.rate == 0.0 ? Eigen::ArrayXd::Ones(total) : Eigen::ArrayXd((e.rate / w).min(1.0));
        t.beyond_weight = e.rate == 0.0 ? 1.0 : std::min(1.0, e.rate / w_last);
        break;
    }
    const double size = e.kind == BandExcitation::Kind::kVelocity ? 1.0 / w(0) : 1.0;
    // Within a quarter of the lowest elastic period of its first change a load has not moved
    // that far yet (nor has an initial velocity): its modes' linear response up to the horizon,
    // through the load's own time function (a jump, a ramp, a table ...; the modes beyond those
    // given respond quasi-statically). A jump late in a run once counted as if it acted from
    // the start (a step at 9 ms of a 10 ms run took 22 modes and left 11 rtol), a load that acts
    // only after the run at its full static response (166 rtol).
    const bool force = e.kind == BandExcitation::Kind::kForce;
    const FactorChanges changes = force ? factor_changes(e, horizon) : FactorChanges{};
    const bool early =
        horizon > 0.0 && lowest_positive > 0.0 &&
        (horizon - changes.start) * std::sqrt(lowest_positive) < 0.5 * std::numbers::pi;
    Eigen::MatrixXd response;  // per mode (from `rigid`) and sample time: g_k(tau_j)
    Eigen::VectorXd change;    // the factor's change at the sample times
    if (early) {
      response.resize(total, kHorizonSamples);
      change.resize(kHorizonSamples);
      for (int j = 0; j < kHorizonSamples; ++j) {
        const double tau = changes.start + (horizon - changes.start) * (j + 1) / kHorizonSamples;
        change(j) = force ? factor_change(changes, tau) : 0.0;
        for (Eigen::Index k = rigid; k < total; ++k)
          response(k, j) = force ? mode_response(changes, w(k), tau) : std::sin(w(k) * tau) / w(k);
      }
    }
    for (int part = 0; part < 2; ++part) {
      const std::vector<Eigen::Index> rows = rows_of(part);
      double reached = 0.0;
      if (early) {
        Eigen::VectorXd beyond = elastic;  // the response of the modes beyond those given
        for (Eigen::Index k = rigid; k < total; ++k) beyond -= t.coefficients(k) * phi.col(k);
        // Per unit factor: a table's coefficients carry its largest value.
        const double unit = force ? 1.0 / e.factor : 1.0;
        for (int j = 0; j < kHorizonSamples; ++j)
          for (Eigen::Index r : rows) {
            double x = force ? beyond(r) * change(j) : 0.0;
            for (Eigen::Index k = rigid; k < total; ++k)
              x += t.coefficients(k) * phi(r, k) * response(k, j);
            reached = std::max(reached, unit * std::abs(x));
          }
      }
      for (Eigen::Index r : rows) {
        const double full = size * std::abs(elastic(r));
        scale[part] = std::max(scale[part], early ? std::min(full, reached) : full);
      }
    }
    tracks.push_back(std::move(t));
  }
  if (!(scale[0] > 0.0) && !(scale[1] > 0.0) && (least <= total || fixed > 0)) {  // nothing rings
    choice.modes = fixed > 0 ? fixed : least;
    choice.met = true;
    return choice;
  }
  // Translations, or rotations when nothing translates (a response point away from a body's
  // centre also moves with its rotation: not in the estimate).
  const std::vector<Eigen::Index> rows = rows_of(scale[0] > 0.0 ? 0 : 1);
  const Eigen::Index translations = scale[0] > 0.0 ? static_cast<Eigen::Index>(rows.size()) : 0;
  const Eigen::Index nr = static_cast<Eigen::Index>(rows.size());
  // Per track and row, from the top mode down: the coherent sum of the ringing of the modes
  // from m up (its value at the start, when every mode is in phase) and its root sum of squares
  // (what it averages to once they have dephased, within 1 / w_m).
  std::vector<Eigen::ArrayXXd> coherent(tracks.size()), squares(tracks.size());
  for (size_t i = 0; i < tracks.size(); ++i) {
    const Track& t = tracks[i];
    // The response of the modes above those given: for a force, the static response to its
    // part outside them, (K0 + mu M0)^-1 (F - M0 Phi Phi^T F), equal to the full response
    // less the modes' but without that difference of two nearly equal numbers (on a
    // 1,000-segment cantilever, K0 + mu M0 has a condition of ~1e12: the full response is
    // good to ~1e-5 of itself, where the part sought is ~1e-7 of it).
    const BandExcitation& e = excitations[i];
    Eigen::VectorXd rest;
    if (e.kind == BandExcitation::Kind::kForce)
      rest = e.factor * shifted.solve(e.vector - m0 * (phi * (phi.transpose() * e.vector)));
    else
      rest = e.vector - phi * (phi.transpose() * (m0 * e.vector));
    Eigen::ArrayXd beyond = Eigen::ArrayXd::Zero(nr);
    if (!complete)
      for (Eigen::Index r = 0; r < nr; ++r) beyond(r) = std::abs(t.beyond_weight * rest(rows[r]));
    coherent[i].resize(nr, total + 1);
    squares[i].resize(nr, total + 1);
    coherent[i].col(total) = beyond;
    squares[i].col(total) = beyond.square();
    for (Eigen::Index k = total - 1; k >= 0; --k)
      for (Eigen::Index r = 0; r < nr; ++r) {
        const double ring = std::abs(t.weights(k) * t.coefficients(k) * phi(rows[r], k));
        coherent[i](r, k) = coherent[i](r, k + 1) + ring;
        squares[i](r, k) = squares[i](r, k + 1) + ring * ring;
      }
  }
  for (Eigen::Index m = fixed > 0 ? std::min(std::max(fixed, rigid), total) : least; m <= total;
       ++m) {
    // At the last mode given, a twin not given may lie just above: only a complete basis ends
    // there (a band given ends where it is given).
    const bool boundary = fixed > 0 || (m == total ? complete
                                                   : lambda(m) - lambda(m - 1) >
                                                         1e-6 * std::abs(lambda(m)) + 1e-10 * top);
    if (!boundary) continue;
    double dropped[2] = {0.0, 0.0};
    for (size_t i = 0; i < tracks.size(); ++i) {
      const Eigen::ArrayXd amplitude =
          coherent[i].col(m).min(kBandPeakOverRms * squares[i].col(m).sqrt());
      if (translations) dropped[0] += amplitude.head(translations).maxCoeff();
      if (nr > translations) dropped[1] += amplitude.tail(nr - translations).maxCoeff();
    }
    choice.modes = m;
    choice.estimate = std::max(scale[0] > 0.0 ? dropped[0] / scale[0] : 0.0,
                               scale[1] > 0.0 ? dropped[1] / scale[1] : 0.0);
    if (choice.estimate <= tolerance || fixed > 0) {
      choice.met = choice.estimate <= tolerance;
      return choice;
    }
  }
  return choice;
}

std::vector<int> watched_bodies(const Model& model) {
  std::vector<int> out, all;
  for (int k = 0; k < model.n_free(); ++k) {
    all.push_back(k);
    if (!model.bodies[model.free_bodies[k]].generated) out.push_back(k);
  }
  return out.empty() ? all : out;
}

std::vector<BandExcitation> band_excitations(const Model& model, const Data& data,
                                             const Eigen::VectorXd& unbalanced,
                                             const Eigen::VectorXd& velocity, double t0,
                                             double horizon) {
  const double t1 = horizon > 0.0 ? t0 + horizon : std::numeric_limits<double>::infinity();
  std::vector<BandExcitation> out;
  if (unbalanced.size() == model.n_dofs && unbalanced.cwiseAbs().maxCoeff() > 0.0)
    out.push_back({BandExcitation::Kind::kForce, unbalanced, 0.0, 1.0});
  if (velocity.size() == model.n_dofs && velocity.cwiseAbs().maxCoeff() > 0.0)
    out.push_back({BandExcitation::Kind::kVelocity, velocity, 0.0, 1.0});
  std::vector<int> free_index(model.bodies.size(), -1);
  for (int k = 0; k < model.n_free(); ++k) free_index[model.free_bodies[k]] = k;
  // Loads on one time function change together: one excitation.
  std::vector<const TimeFunction*> functions(out.size(), nullptr);
  for (const Load& load : model.loads) {
    const int k = free_index[load.body];
    double rate = 0.0, factor = 1.0;
    if (k < 0 || !change_after(load.time, t0, t1, &rate, &factor)) continue;
    size_t slot = 0;
    while (slot < out.size() && !(functions[slot] && same_function(*functions[slot], load.time)))
      ++slot;
    if (slot == out.size()) {
      out.push_back({BandExcitation::Kind::kForce, Eigen::VectorXd::Zero(model.n_dofs), rate,
                     factor, load.time.type == TimeFunction::Type::kHarmonic, &load.time, t0});
      functions.push_back(&load.time);
    }
    const Pose<double>& pose = data.pose[load.body];
    const Vec3 value = load.follows ? Vec3(pose.A * load.value) : load.value;
    Eigen::VectorXd& f = out[slot].vector;
    if (load.kind == LoadKind::kForce) {
      f.segment<3>(kD * k) += value;
      f.segment<3>(kD * k + 3) += (pose.A * load.offset).cross(value);
    } else {
      f.segment<3>(kD * k + 3) += value;
    }
  }
  return out;
}

namespace {

bool band_fail(std::string* error, const std::string& what) {
  *error = what;
  return false;
}

}  // namespace

bool solve_band_modes(const Model& model, const Data& data, double t0,
                      const Eigen::SparseMatrix<double>& k0, const Eigen::SparseMatrix<double>& m0,
                      double band_hz, const std::vector<BandExcitation>& excitations,
                      const std::vector<int>& watched, double rtol, double max_seconds,
                      BandModes& out, std::string* error, double horizon) {
  const bool choose = !(band_hz > 0.0);
  double limit = choose ? 0.0 : std::pow(2.0 * std::numbers::pi * band_hz, 2);
  const Eigen::Index n = model.n_dofs;
  const double seconds = max_seconds;
  Eigen::VectorXd& values = out.values;
  Eigen::MatrixXd& vectors = out.vectors;
  out = BandModes();
  BandChoice chosen;
  const auto estimate = [&](Eigen::Index fixed = 0) {
    // A given band's rigid and mechanism modes: the lowest that deform no element (choose_band).
    Eigen::Index rigid = -1;
    if (fixed > 0) {
      const ElementDeformation deformation(model, data);
      rigid = 0;
      while (rigid < values.size() &&
             deformation.ratio(vectors.col(rigid)) <= kRigidModeDeformation)
        ++rigid;
    }
    // A shift of a hundredth of the lowest positive w^2 keeps rigid and mechanism modes
    // regular (they are kept).
    const double top = values.cwiseAbs().maxCoeff();
    double mu = 0.0;
    for (Eigen::Index i = std::max<Eigen::Index>(rigid, 0); i < values.size() && mu == 0.0; ++i)
      if (rigid >= 0 ? values(i) > 0.0 : values(i) > 1e-8 * top) mu = 0.01 * values(i);
    if (mu == 0.0) mu = 1.0;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> shifted(
        Eigen::SparseMatrix<double>(k0 + mu * m0));
    if (shifted.info() != Eigen::Success) return false;
    chosen = choose_band(values, vectors, m0, shifted, mu, excitations, watched, rtol, horizon,
                         fixed, rigid);
    return true;
  };
  // Every mode from the dense eigensolver (and the band chosen from them).
  const auto dense = [&]() {
    if (!solve_dense_eigenproblem(Eigen::MatrixXd(k0), Eigen::MatrixXd(m0), values, vectors))
      return band_fail(error, "the modal integrator's eigensolver failed");
    if (choose && !estimate())
      return band_fail(error,
                       "the modal integrator: the stiffness where it is linearized is singular");
    return true;
  };
  // Up to kModalIntegratorMaxDofs, when no band of the modes Lanczos gives meets rtol, every mode
  // from the dense eigensolver (docs/transient_measurements.md "Every mode where no band meets
  // rtol"). Its estimate counts each mode above a band apart where Lanczos's sums the static
  // response of the modes beyond those given: with every mode at once, the 201-segment cantilever
  // at rtol 1e-6 needed all 1,206 modes (5.0 s) where 192 from Lanczos chose 155 (1.3 s; 0.25 rtol
  // off).
  const bool dense_after = choose && n <= kModalIntegratorMaxDofs;
  if (n <= kModalDenseBandMaxDofs) {
    if (!dense()) return false;
  } else {
    ModalOptions mo;
    mo.time = t0;
    mo.solver = EigenSolverKind::kShiftInvert;
    const int most =
        static_cast<int>(std::min<Eigen::Index>(n - 12, choose ? kModalChosenBandMaxModes : n));
    for (int wanted = std::min(24, most);; wanted = std::min(2 * wanted, most)) {
      mo.modes = wanted;
      if (seconds < 1e7) mo.max_seconds = std::max(1e-3, seconds);
      Data d = data;
      const ModalResult r = solve_modal(model, mo, d);
      if (!r.ok) return band_fail(error, "the modal integrator's eigensolver: " + r.message);
      std::vector<size_t> order(r.modes.size());
      for (size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::sort(order.begin(), order.end(),
                [&](size_t a, size_t b) { return r.modes[a].eigenvalue < r.modes[b].eigenvalue; });
      values.resize(static_cast<Eigen::Index>(order.size()));
      vectors.resize(n, values.size());
      for (Eigen::Index i = 0; i < values.size(); ++i) {
        values(i) = r.modes[order[i]].eigenvalue;
        vectors.col(i) = r.modes[order[i]].shape;
      }
      const bool all = wanted >= most;
      if (choose) {
        if (!estimate())
          return band_fail(
              error, "the modal integrator: the stiffness where it is linearized is singular");
        if (chosen.met || all) break;
      } else if ((values.size() && values(values.size() - 1) > limit) || all) {
        break;
      }
    }
    if (dense_after && !chosen.met && !dense()) return false;
  }
  if (choose) {
    if (!chosen.met) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "no band of the %ld lowest modes (up to %.4g Hz) keeps the ringing of the "
                    "modes above it within rtol (%.2g of the motion estimated for all %ld)",
                    static_cast<long>(values.size()),
                    std::sqrt(std::max(0.0, values(values.size() - 1))) / (2.0 * std::numbers::pi),
                    chosen.estimate, static_cast<long>(values.size()));
      return band_fail(error, text);
    }
    // Beyond half the modes, the products with n x m matrices and the quasi-static iteration
    // cost more than the full basis's n x n products: all modes then (exact, no band).
    const bool all = values.size() == n && 2 * chosen.modes > n;
    out.kept = all ? n : chosen.modes;
    out.needed = chosen.modes;
    if (all) {
      chosen.modes = n;
      chosen.estimate = 0.0;
    }
    // The band's top: the highest mode kept, or the lowest elastic one when only rigid and
    // mechanism modes are (the shift below must not vanish).
    const double top = values.cwiseAbs().maxCoeff();
    limit = values(chosen.modes - 1);
    for (Eigen::Index i = 0; i < values.size() && !(limit > 1e-8 * top); ++i)
      limit = std::max(limit, values(i));
    out.estimate = chosen.estimate;
  } else {
    out.kept = 0;
    while (out.kept < values.size() && values(out.kept) <= limit) ++out.kept;
    // What the given band drops, by the same estimate (a band below the ringing of an initial
    // velocity or a load's jump once said only what the quasi-static modes' inertia left).
    if (out.kept > 0 && out.kept < n && !excitations.empty() && estimate(out.kept))
      out.given_estimate = chosen.estimate;
  }
  out.top = limit;
  if (out.kept == 0)
    return band_fail(error, "no mode lies below max_frequency_hz = " + std::to_string(band_hz));
  // (A chosen band keeps at least one mode: choose_band's least.)
  return true;
}

}  // namespace beamrail
