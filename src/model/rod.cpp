#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <tubeplan/model/rod.hpp>

namespace tubeplan::model {

namespace {

using Order = std::array<int, Rod::kMaxLoads>;

// The loads' indices sorted by arc position (insertion sort: at most 16, and stable, so that the
// integration visits loads in a fixed order whatever the caller's).
int SortedOrder(std::span<const RodLoad> loads, Order& order) {
  const int count = static_cast<int>(loads.size());
  assert(count <= Rod::kMaxLoads);
  for (int i = 0; i < count; ++i) {
    int at = i;
    while (at > 0 &&
           loads[std::size_t(order[std::size_t(at - 1)])].s_m > loads[std::size_t(i)].s_m) {
      order[std::size_t(at)] = order[std::size_t(at - 1)];
      --at;
    }
    order[std::size_t(at)] = i;
  }
  return count;
}

// The rotation matrix of rotation vector w (Rodrigues). A step of the rod turns by h kappa,
// rarely more than 0.05 rad: there the series to theta^4 leave out theta^6 / 5040 < 4e-12 and
// spare the sine and cosine that otherwise dominate the integration's cost.
inline Eigen::Matrix3d Rotation(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  double a, b;  // sin(theta) / theta, (1 - cos(theta)) / theta^2
  if (theta2 < 2.5e-3) {
    a = 1.0 - theta2 / 6.0 * (1.0 - theta2 / 20.0);
    b = 0.5 - theta2 / 24.0 * (1.0 - theta2 / 30.0);
  } else {
    const double theta = std::sqrt(theta2);
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
  }
  // I + a W + b W^2 with W^2 = w w^T - theta^2 I, entry by entry: a third of the products of
  // forming W^2 (a rotation a step, the integration's largest cost after the frame's product).
  const double diagonal = 1.0 - b * theta2;
  const double bxy = b * w.x() * w.y(), bxz = b * w.x() * w.z(), byz = b * w.y() * w.z();
  const double ax = a * w.x(), ay = a * w.y(), az = a * w.z();
  Eigen::Matrix3d G;
  G << diagonal + b * w.x() * w.x(), bxy - az, bxz + ay,  //
      bxy + az, diagonal + b * w.y() * w.y(), byz - ax,   //
      bxz - ay, byz + ax, diagonal + b * w.z() * w.z();
  return G;
}

// The largest moment the loads can make about the clamp (each force by its lever along the
// straight rod and its offset): the scale of the shooting residual.
double MomentScale(std::span<const RodLoad> loads) {
  double scale = 0.0;
  for (const RodLoad& load : loads) scale += load.f_N.norm() * (load.s_m + load.r_m.norm());
  return scale;
}

}  // namespace

Rod::Rod(double bending_stiffness_Nm2, double max_step_m)
    : EI_(bending_stiffness_Nm2), max_step_m_(max_step_m) {
  if (!(EI_ > 0.0) || !std::isfinite(EI_) || !(max_step_m_ > 0.0) || !std::isfinite(max_step_m_))
    throw std::invalid_argument("Rod: bending stiffness and step must be positive and finite");
}

// Forward sensitivities: the linearisation of each step of the integration applied to a set of
// directions of its inputs alongside it. They are the derivatives of the discrete map itself (not
// of the continuous rod), so Newton on them converges as on the exact Jacobian and the compliance
// is the discrete chain's; one integration carries them all, where differences took one per
// direction. Direction c < 3 turns the end section by the unit turn about axis c (Q -> Exp(e_c) Q,
// clamp frame, as Newton's step); direction 3 + 3 j + c, when asked for, moves load j's force
// (its index in the caller's span) along axis c by a unit at the integration's scale.
template <int kMaxDirections>
struct Rod::Tangent {
  int directions = 0;  ///< 3 (the end's turn), or 3 + 3 count (and each load's force)
  /// Per direction, at the current node: the section's turn w (R -> Exp(w) R), the moment's and
  /// the force's derivatives, and the centre's (relative to the end, as the integration's x).
  std::array<Eigen::Vector3d, kMaxDirections> turn, m, n, x;
  /// At the root: the residual's derivative per direction.
  std::array<Eigen::Vector3d, kMaxDirections> residual;
  /// At the samples, when the caller gives `surface_r_m` (one offset per sample): the derivative
  /// of the sample's surface point p + R R*^T r (R* the integration's own frame there), relative
  /// to the root like the samples' positions. surface[k * kMaxDirections + c].
  std::span<const Eigen::Vector3d> surface_r_m;
  std::array<Eigen::Vector3d, std::size_t(kMaxDirections) * Rod::kMaxLoads> surface;
};

Rod::Result Rod::Integrate(std::span<const RodLoad> loads, std::span<const int> order, double scale,
                           const Eigen::Matrix3d& Q, const RodSamples& samples) const {
  return Integrate<0>(loads, order, scale, Q, samples, nullptr);
}

template <int kMaxDirections>
Rod::Result Rod::Integrate(std::span<const RodLoad> loads, std::span<const int> order, double scale,
                           const Eigen::Matrix3d& Q, const RodSamples& samples,
                           Tangent<kMaxDirections>* tangent) const {
  constexpr bool kTangent = kMaxDirections > 0;
  const int count = static_cast<int>(order.size());
  const double end = count > 0 ? loads[std::size_t(order[std::size_t(count - 1)])].s_m : 0.0;
  // From the last load back to the clamp: beyond it the moment and force are zero; passing a
  // load adds its force and its moment about the centre.
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  // relative to the end; shifted at the root
  Eigen::Matrix3d R = Q;
  Result result;
  const auto perp_norm = [&](const Eigen::Vector3d& v) {
    const Eigen::Vector3d t = R.col(2);
    return (v - v.dot(t) * t).norm();
  };
  int directions = 0;
  bool force_directions = false;  // whether any direction moves a force (else dn = 0 throughout)
  // The directions the steps carry: the end's turn, and a load's force from where the
  // integration passes the load. Beyond the load that direction is zero (the step's
  // linearisation is linear in w, dm and dn, all zero there), so its steps would compute zeros
  // only: skipping them changes no result but the sign of a zero, and spares the compliance
  // ~15 % of its time in the groove's graph (its loads spread along the tube).
  //
  // The active directions are carried component by component, one array per component, in the
  // order they became active (slot a holds direction active[a]): the step's loop over them then
  // runs over contiguous doubles, which the compiler vectorises. The arithmetic per direction
  // is Eigen's for the same expressions, operation for operation (the same bits); `tangent`'s
  // vectors are brought up to date where they are read (the samples, the root).
  std::array<int, std::size_t(kMaxDirections)> active{};
  int active_count = 0;
  using Slots = std::array<double, std::size_t(kMaxDirections)>;
  std::array<Slots, 3> sw, sm, sn, sx;  // turn, moment, force, centre derivatives; per axis
  const auto add_slot = [&](int d) {
    const std::size_t a = std::size_t(active_count++), dd = std::size_t(d);
    active[a] = d;
    for (int i = 0; i < 3; ++i) {
      sw[std::size_t(i)][a] = tangent->turn[dd][i];
      sm[std::size_t(i)][a] = tangent->m[dd][i];
      sn[std::size_t(i)][a] = tangent->n[dd][i];
      sx[std::size_t(i)][a] = tangent->x[dd][i];
    }
  };
  const auto sync = [&] {  // slots -> tangent
    for (int a = 0; a < active_count; ++a) {
      const std::size_t aa = std::size_t(a), dd = std::size_t(active[aa]);
      tangent->turn[dd] = Eigen::Vector3d(sw[0][aa], sw[1][aa], sw[2][aa]);
      tangent->m[dd] = Eigen::Vector3d(sm[0][aa], sm[1][aa], sm[2][aa]);
      tangent->n[dd] = Eigen::Vector3d(sn[0][aa], sn[1][aa], sn[2][aa]);
      tangent->x[dd] = Eigen::Vector3d(sx[0][aa], sx[1][aa], sx[2][aa]);
    }
  };
  if constexpr (kTangent) {
    directions = tangent->directions;
    assert(directions <= kMaxDirections &&
           (directions == 3 || directions == 3 + 3 * count || directions == 6 + 3 * count));
    force_directions = directions > 3;
    // Directions 3 + 3 count + c (when asked for) add a unit moment about axis c to the end
    // section: active from the start, like the end's turn.
    const int first_moment = directions == 6 + 3 * count ? 3 + 3 * count : directions;
    for (int c = 0; c < directions; ++c) {
      const std::size_t cc = std::size_t(c);
      tangent->turn[cc] =
          c < 3 ? Eigen::Vector3d(Eigen::Vector3d::Unit(c)) : Eigen::Vector3d::Zero();
      tangent->m[cc] = c >= first_moment ? Eigen::Vector3d(Eigen::Vector3d::Unit(c - first_moment))
                                         : Eigen::Vector3d::Zero();
      tangent->n[cc].setZero();
      tangent->x[cc].setZero();
    }
    for (int c = 0; c < 3; ++c) add_slot(c);
    for (int c = first_moment; c < directions; ++c) add_slot(c);
  }
  const std::size_t sample_count = samples.s_m.size();
  std::size_t beyond = sample_count;  // samples at s > end: straight, set at the end
  while (beyond > 0 && samples.s_m[beyond - 1] > end) --beyond;
  std::size_t next_sample = beyond;  // samples [0, next_sample) are still to be recorded
  const auto record = [&](double s) {
    while (next_sample > 0 && samples.s_m[next_sample - 1] >= s) {
      --next_sample;
      samples.p_m[next_sample] = x;
      if (!samples.R.empty()) samples.R[next_sample] = R;
      if constexpr (kTangent) {
        if (!tangent->surface_r_m.empty()) {
          sync();
          const Eigen::Vector3d& r = tangent->surface_r_m[next_sample];
          for (int c = 0; c < directions; ++c)
            tangent->surface[next_sample * kMaxDirections + std::size_t(c)] =
                tangent->x[std::size_t(c)] + tangent->turn[std::size_t(c)].cross(r);
        }
      }
    }
  };
  double s = end;
  int next_load = count - 1;
  for (;;) {
    while (next_load >= 0 && loads[std::size_t(order[std::size_t(next_load)])].s_m >= s) {
      const int j = order[std::size_t(next_load--)];
      const RodLoad& load = loads[std::size_t(j)];
      const Eigen::Vector3d f = scale * load.f_N;
      m += load.r_m.cross(f);
      n += f;
      result.max_moment_Nm = std::max(result.max_moment_Nm, perp_norm(m));
      if constexpr (kTangent) {
        if (force_directions)
          for (int c = 0; c < 3; ++c) {
            const std::size_t cc = std::size_t(3 + 3 * j + c);
            tangent->n[cc] += scale * Eigen::Vector3d::Unit(c);
            tangent->m[cc] += scale * load.r_m.cross(Eigen::Vector3d::Unit(c));
            if constexpr (kMaxDirections > 3) add_slot(int(cc));
          }
      }
    }
    record(s);
    if (s <= 0.0) break;
    double stop = 0.0;
    if (next_load >= 0)
      stop = std::max(stop, loads[std::size_t(order[std::size_t(next_load)])].s_m);
    if (next_sample > 0) stop = std::max(stop, samples.s_m[next_sample - 1]);
    // An interval no longer than a step (the usual one: the samples are the chain's nodes,
    // closer than max_step_m_) is one step: its quotient is at most 1 (rounding is monotonic),
    // so the ceiling below is at most 1 and the count 1 either way, without the ceiling's
    // rounding sequence (no SSE4.1 round instruction here).
    const double span_m = s - stop;
    const int steps = span_m <= max_step_m_
                          ? 1
                          : std::max(1, static_cast<int>(std::ceil(span_m / max_step_m_ - 1e-9)));
    const double h = (s - stop) / steps;
    for (int k = 0; k < steps; ++k) {
      const Eigen::Vector3d t = R.col(2);
      // The moment and the tangent at the step's middle, predicted (m' = -t x n, t' = m x t / EI,
      // here backwards); the step turns the section by h times the curvature there (across the
      // tangent: the rod does not twist).
      const Eigen::Vector3d m_mid = m + 0.5 * h * t.cross(n);
      const double c_u = 0.5 * h / EI_;
      const Eigen::Vector3d u = t - c_u * m_mid.cross(t);
      const double u_norm = u.norm();
      const Eigen::Vector3d t_mid = u / u_norm;
      const double m_along = m_mid.dot(t_mid);
      const Eigen::Vector3d kappa = (m_mid - m_along * t_mid) / EI_;
      const Eigen::Vector3d turn = -h * kappa;
      const Eigen::Matrix3d G = Rotation(turn);
      const Eigen::Matrix3d R_before = G * R;
      const Eigen::Vector3d t_before = R_before.col(2);
      // The chord of an arc of length h whose tangent turns from t_before to t.
      // sin(half) / half with sin(half) = s: s / asin(s) = 1 - s^2/6 - 17 s^4/360 - ..., whose
      // next term is below 1e-10 for turns up to 0.05 rad.
      const Eigen::Vector3d t_diff = t - t_before, t_sum = t + t_before;
      const double sin_half = 0.5 * t_diff.norm();
      const double cos_half = 0.5 * t_sum.norm();
      const double s2 = sin_half * sin_half;
      const bool series = s2 < 6.25e-4;
      const double half = series ? 0.0 : std::atan2(sin_half, cos_half);
      const double chord =
          series ? h * (1.0 - s2 / 6.0 - 17.0 / 360.0 * s2 * s2) : h * sin_half / half;
      const bool arc = cos_half > 1e-12;
      const Eigen::Vector3d dx = arc ? Eigen::Vector3d(chord * t_sum / (2.0 * cos_half)) : t * h;
      if constexpr (kTangent) {
        // The step's linearisation: the same formulas differentiated, in the same order.
        // d Exp(v) = [J_l(v) dv]x Exp(v), J_l = I + b [v]x + c [v]x^2 with b = (1 - cos)/theta^2
        // and c = (theta - sin)/theta^3, by series below the same 0.05 rad as Rotation.
        const double theta2 = turn.squaredNorm();
        double b, c;
        if (theta2 < 2.5e-3) {
          b = 0.5 - theta2 / 24.0 * (1.0 - theta2 / 30.0);
          c = 1.0 / 6.0 - theta2 / 120.0 * (1.0 - theta2 / 42.0);
        } else {
          const double theta = std::sqrt(theta2);
          b = (1.0 - std::cos(theta)) / theta2;
          c = (theta - std::sin(theta)) / (theta2 * theta);
        }
        // d chord / d s2, s2 = sin(half)^2 = |t - t_before|^2 / 4.
        const double dchord_ds2 =
            series ? h * (-1.0 / 6.0 - 17.0 / 180.0 * s2)
                   : h * (half * cos_half - sin_half) / (half * half * 2.0 * sin_half * cos_half);
        const Eigen::Vector3d along = t_sum / (2.0 * cos_half);  // the chord's direction
        // Per direction (slot a), in the components of W: with w the section's turn, dm, dn and
        // dx the moment's, force's and centre's derivatives,
        //   dt = w x t, dm_mid = dm + h/2 dt x n (+ h/2 t x dn), du = dt - c_u (dm_mid x t +
        //   m_mid x dt), dt_mid = (du - (t_mid.du) t_mid) / |u|, dturn = -h/EI (dm_mid -
        //   (t_mid.dm_mid + m_mid.dt_mid) t_mid - m_along dt_mid), w_before = dturn + b v x
        //   dturn + c v x (v x dturn) + G w (v the step's turn), dt_before = w_before x
        //   t_before, ddx the chord's derivative; then dm += ddx x n (+ dx x dn), dx -= ddx.
        const double hh = 0.5 * h, k_turn = -h / EI_, den = 2.0 * cos_half;
        const double tx = t.x(), ty = t.y(), tz = t.z();
        const double nx = n.x(), ny = n.y(), nz = n.z();
        const double mmx = m_mid.x(), mmy = m_mid.y(), mmz = m_mid.z();
        const double tmx = t_mid.x(), tmy = t_mid.y(), tmz = t_mid.z();
        const double vx = turn.x(), vy = turn.y(), vz = turn.z();
        const double tbx = t_before.x(), tby = t_before.y(), tbz = t_before.z();
        const double tdx = t_diff.x(), tdy = t_diff.y(), tdz = t_diff.z();
        const double alx = along.x(), aly = along.y(), alz = along.z();
        const double dxx = dx.x(), dxy = dx.y(), dxz = dx.z();
        const double g00 = G(0, 0), g01 = G(0, 1), g02 = G(0, 2), g10 = G(1, 0), g11 = G(1, 1),
                     g12 = G(1, 2), g20 = G(2, 0), g21 = G(2, 1), g22 = G(2, 2);
        double* const wx = sw[0].data();
        double* const wy = sw[1].data();
        double* const wz = sw[2].data();
        double* const mx = sm[0].data();
        double* const my = sm[1].data();
        double* const mz = sm[2].data();
        const double* const dnx = sn[0].data();
        const double* const dny = sn[1].data();
        const double* const dnz = sn[2].data();
        double* const xx = sx[0].data();
        double* const xy = sx[1].data();
        double* const xz = sx[2].data();
        // The loop without branches, one version per case, so that the compiler vectorises it.
        const auto directions_step = [=](auto with_forces, auto on_arc) {
          constexpr bool kForces = decltype(with_forces)::value;
          constexpr bool kArc = decltype(on_arc)::value;
          for (int a = 0; a < active_count; ++a) {
            const double dtx = wy[a] * tz - wz[a] * ty;
            const double dty = wz[a] * tx - wx[a] * tz;
            const double dtz = wx[a] * ty - wy[a] * tx;
            double dmmx = mx[a] + hh * (dty * nz - dtz * ny);
            double dmmy = my[a] + hh * (dtz * nx - dtx * nz);
            double dmmz = mz[a] + hh * (dtx * ny - dty * nx);
            if constexpr (kForces) {
              dmmx = dmmx + hh * (ty * dnz[a] - tz * dny[a]);
              dmmy = dmmy + hh * (tz * dnx[a] - tx * dnz[a]);
              dmmz = dmmz + hh * (tx * dny[a] - ty * dnx[a]);
            }
            const double dux = dtx - c_u * ((dmmy * tz - dmmz * ty) + (mmy * dtz - mmz * dty));
            const double duy = dty - c_u * ((dmmz * tx - dmmx * tz) + (mmz * dtx - mmx * dtz));
            const double duz = dtz - c_u * ((dmmx * ty - dmmy * tx) + (mmx * dty - mmy * dtx));
            const double tm_du = tmx * dux + tmy * duy + tmz * duz;
            const double dtmx = (dux - tm_du * tmx) / u_norm;
            const double dtmy = (duy - tm_du * tmy) / u_norm;
            const double dtmz = (duz - tm_du * tmz) / u_norm;
            const double along_t =
                (tmx * dmmx + tmy * dmmy + tmz * dmmz) + (mmx * dtmx + mmy * dtmy + mmz * dtmz);
            const double drx = k_turn * ((dmmx - along_t * tmx) - m_along * dtmx);
            const double dry = k_turn * ((dmmy - along_t * tmy) - m_along * dtmy);
            const double drz = k_turn * ((dmmz - along_t * tmz) - m_along * dtmz);
            const double px = vy * drz - vz * dry;  // v x dturn
            const double py = vz * drx - vx * drz;
            const double pz = vx * dry - vy * drx;
            const double qx = vy * pz - vz * py;  // v x (v x dturn)
            const double qy = vz * px - vx * pz;
            const double qz = vx * py - vy * px;
            // G w as Eigen sums it (rows 0 and 1 as one packet, row 2 by a scalar reduction).
            const double gwx = (g00 * wx[a] + g01 * wy[a]) + g02 * wz[a];
            const double gwy = (g10 * wx[a] + g11 * wy[a]) + g12 * wz[a];
            const double gwz = g20 * wx[a] + (g21 * wy[a] + g22 * wz[a]);
            const double wbx = ((drx + b * px) + c * qx) + gwx;
            const double wby = ((dry + b * py) + c * qy) + gwy;
            const double wbz = ((drz + b * pz) + c * qz) + gwz;
            double ddxx, ddxy, ddxz;
            if constexpr (kArc) {
              const double dtbx = wby * tbz - wbz * tby;  // dt_before = w_before x t_before
              const double dtby = wbz * tbx - wbx * tbz;
              const double dtbz = wbx * tby - wby * tbx;
              const double ds2 =
                  0.5 * ((tdx * (dtx - dtbx) + tdy * (dty - dtby)) + tdz * (dtz - dtbz));
              const double dsx = dtx + dtbx, dsy = dty + dtby, dsz = dtz + dtbz;
              const double al_ds = (alx * dsx + aly * dsy) + alz * dsz;
              const double dalx = (dsx - al_ds * alx) / den;
              const double daly = (dsy - al_ds * aly) / den;
              const double dalz = (dsz - al_ds * alz) / den;
              const double k_chord = dchord_ds2 * ds2;
              ddxx = k_chord * alx + chord * dalx;
              ddxy = k_chord * aly + chord * daly;
              ddxz = k_chord * alz + chord * dalz;
            } else {
              ddxx = h * dtx;
              ddxy = h * dty;
              ddxz = h * dtz;
            }
            mx[a] = mx[a] + (ddxy * nz - ddxz * ny);
            my[a] = my[a] + (ddxz * nx - ddxx * nz);
            mz[a] = mz[a] + (ddxx * ny - ddxy * nx);
            if constexpr (kForces) {
              mx[a] = mx[a] + (dxy * dnz[a] - dxz * dny[a]);
              my[a] = my[a] + (dxz * dnx[a] - dxx * dnz[a]);
              mz[a] = mz[a] + (dxx * dny[a] - dxy * dnx[a]);
            }
            xx[a] = xx[a] - ddxx;
            xy[a] = xy[a] - ddxy;
            xz[a] = xz[a] - ddxz;
            wx[a] = wbx;
            wy[a] = wby;
            wz[a] = wbz;
          }
        };
        using Yes = std::true_type;
        using No = std::false_type;
        if (force_directions) {
          if (arc)
            directions_step(Yes{}, Yes{});
          else
            directions_step(Yes{}, No{});
        } else {
          if (arc)
            directions_step(No{}, Yes{});
          else
            directions_step(No{}, No{});
        }
      }
      m += dx.cross(n);  // exact for the chord: equilibrium of the discrete chain
      x -= dx;
      R = R_before;
      result.energy_J += 0.5 * h * EI_ * kappa.squaredNorm();
      result.max_moment_Nm = std::max(result.max_moment_Nm, perp_norm(m));
      s = k + 1 == steps ? stop : s - h;
    }
  }
  // Positions from the root; beyond the last load the rod is straight along its end tangent.
  const Eigen::Vector3d root = x;
  for (std::size_t k = 0; k < beyond; ++k) samples.p_m[k] -= root;
  result.end_p = -root;
  for (std::size_t k = beyond; k < sample_count; ++k) {
    samples.p_m[k] = result.end_p + (samples.s_m[k] - end) * Q.col(2);
    if (!samples.R.empty()) samples.R[k] = Q;
  }
  // The root section must be the clamp's: the residual is its rotation from it (twice the
  // quaternion's vector part, taken with w >= 0 so that only the identity is a zero).
  Eigen::Quaterniond q(R);
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  result.residual = 2.0 * q.vec();
  result.root_moment = m;
  if constexpr (kTangent) {
    sync();
    // R -> Exp(w) R moves the quaternion by (0, w/2) q to first order: d (2 vec) = q_w w + w x vec.
    for (int d = 0; d < directions; ++d) {
      const std::size_t dd = std::size_t(d);
      const Eigen::Vector3d& w = tangent->turn[dd];
      tangent->residual[dd] = q.w() * w + w.cross(q.vec());
    }
    // The samples' surface points are relative to the root: its motion comes off them.
    if (!tangent->surface_r_m.empty())
      for (std::size_t k = 0; k < beyond; ++k)
        for (int d = 0; d < directions; ++d)
          tangent->surface[k * kMaxDirections + std::size_t(d)] -= tangent->x[std::size_t(d)];
  }
  return result;
}

void Rod::ShapeBuffers::Accept() const {
  std::copy(trial.p_m.begin(), trial.p_m.end(), shape.p_m.begin());
  std::copy(trial.R.begin(), trial.R.end(), shape.R.begin());
}

bool Rod::Newton(std::span<const RodLoad> loads, std::span<const int> order, double scale,
                 int max_iterations, Eigen::Matrix3d& Q, Eigen::Matrix3d& jacobian_inv,
                 int& iterations, Result& result, const ShapeBuffers& buffers) const {
  // Solved until the clamp's section is within 1e-10 rad of the clamp: the shape is then within
  // 1e-10 l of the discrete rod's exact equilibrium (15 pm for the rubber tube, 1.5e-7 N of
  // penalty at K = 1e4 N/m), six orders of magnitude below the discretisation's own error
  // (~1e-4 l, rod_test.cpp) and below anything a contact decision sees. A tighter tolerance
  // (it was ~5e-13, a few times the steps' rounding) cost a chord iteration more a solve: 16 %
  // of a tick with the side lying along the floor (bench core.side_on_floor).
  constexpr double kTolerance_rad = 1e-10;
  result = Integrate(loads, order, scale, Q, buffers.shape);
  // Chord iterations with the Jacobian of an earlier solve, while each at least halves the
  // residual (a rod loaded a little differently from last tick). Each accepted step corrects
  // the inverse Jacobian by Broyden's rank-one update (the secant through the two iterates), so
  // the iterations converge superlinearly where the old Jacobian alone contracts only by the
  // loads' relative change per step.
  for (int it = 0; it < 6 && !jacobian_inv.isZero(0.0); ++it) {
    if (!(result.residual.norm() > kTolerance_rad)) return result.residual.allFinite();
    Eigen::Vector3d step = -jacobian_inv * result.residual;
    if (!step.allFinite() || step.norm() > 0.5) break;
    const Eigen::Matrix3d trial = Rotation(step) * Q;
    const Result r = Integrate(loads, order, scale, trial, buffers.trial);
    ++iterations;
    if (!(r.residual.norm() < 0.5 * result.residual.norm())) break;
    buffers.Accept();
    // H += (s - H y) s^T H / (s^T H y), y the residual's change over the step s.
    const Eigen::Vector3d H_y = jacobian_inv * (r.residual - result.residual);
    const double s_H_y = step.dot(H_y);
    if (std::abs(s_H_y) > 1e-3 * step.squaredNorm())
      jacobian_inv += (step - H_y) * (step.transpose() * jacobian_inv) / s_H_y;
    Q = trial;
    result = r;
  }
  // Newton, its Jacobian carried by the integrations (Tangent): each trial's is the next
  // iteration's, so an iteration costs one integration with three directions.
  Tangent<3> tangent;
  tangent.directions = 3;
  bool have_jacobian = false;
  Eigen::Matrix3d J;
  const auto jacobian = [&] {
    for (int c = 0; c < 3; ++c) J.col(c) = tangent.residual[std::size_t(c)];
  };
  // Converged: the Jacobian at the solution itself (its trial's, free) is handed to the next solve.
  const auto done = [&] {
    if (have_jacobian && std::abs(J.determinant()) > 1e-12 && J.allFinite())
      jacobian_inv = J.inverse();
    return result.residual.allFinite();
  };
  for (int it = 0; it < max_iterations; ++it) {
    if (!(result.residual.norm() > kTolerance_rad)) return done();
    ++iterations;
    if (!have_jacobian) {
      result = Integrate(loads, order, scale, Q, buffers.shape, &tangent);
      jacobian();
    }
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-12) || !J.allFinite()) return false;
    jacobian_inv = J.inverse();
    Eigen::Vector3d step = -jacobian_inv * result.residual;
    // At most half a radian a step: the map is far from linear over larger turns.
    if (step.norm() > 0.5) step *= 0.5 / step.norm();
    // Damped: halve the step until the residual falls.
    bool improved = false;
    for (double lambda = 1.0; lambda > 1.0 / 128.0; lambda *= 0.5) {
      const Eigen::Matrix3d trial = Rotation(lambda * step) * Q;
      const Result r = Integrate(loads, order, scale, trial, buffers.trial, &tangent);
      if (r.residual.allFinite() && r.residual.norm() < result.residual.norm()) {
        Q = trial;
        result = r;
        buffers.Accept();
        jacobian();
        have_jacobian = true;
        improved = true;
        break;
      }
    }
    if (!improved) return false;
  }
  return !(result.residual.norm() > kTolerance_rad) && done();
}

RodSolution Rod::Solve(std::span<const RodLoad> loads, const Eigen::Matrix3d& end_R_guess) const {
  return SolveFrom(loads, end_R_guess, Eigen::Matrix3d::Zero(), {});
}

RodSolution Rod::Solve(std::span<const RodLoad> loads, const RodSolution& previous) const {
  return SolveFrom(loads, previous.end_R, previous.jacobian_inv, {});
}

RodSolution Rod::Solve(std::span<const RodLoad> loads, const RodSolution& previous,
                       const RodSamples& shape) const {
  return SolveFrom(loads, previous.end_R, previous.jacobian_inv, shape);
}

RodSolution Rod::SolveFrom(std::span<const RodLoad> loads, const Eigen::Matrix3d& end_R_guess,
                           const Eigen::Matrix3d& jacobian_inv, const RodSamples& shape) const {
  Order order{};
  const int count = SortedOrder(loads, order);
  const std::span<const int> sorted(order.data(), std::size_t(count));
  const std::size_t sample_count = shape.s_m.size();
  bool samples_ok = sample_count <= std::size_t(kMaxShapeSamples) &&
                    shape.p_m.size() == sample_count &&
                    (shape.R.empty() || shape.R.size() == sample_count);
  // Ascending and finite from 0: Integrate records every such sample (Shape's contract), so the
  // accepted trial's buffer is written through before it is copied.
  for (std::size_t k = 0; k < sample_count && samples_ok; ++k)
    samples_ok = shape.s_m[k] >= (k == 0 ? 0.0 : shape.s_m[k - 1]) && std::isfinite(shape.s_m[k]);
  if (!samples_ok)
    throw std::invalid_argument(
        "Rod::Solve: the shape's samples must be at most kMaxShapeSamples arc positions, "
        "ascending, finite and >= 0, with spans of their size");
  // Where trial integrations draw the shape until one is accepted (not zeroed: written before
  // read).
  std::array<Eigen::Vector3d, kMaxShapeSamples> trial_p;
  std::array<Eigen::Matrix3d, kMaxShapeSamples> trial_R;
  const ShapeBuffers buffers{
      shape, RodSamples{shape.s_m, std::span(trial_p.data(), sample_count),
                        std::span(trial_R.data(), shape.R.empty() ? 0 : sample_count)}};
  RodSolution solution;
  Result result;
  Eigen::Matrix3d Q = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d J_inv = jacobian_inv.allFinite() ? jacobian_inv : Eigen::Matrix3d::Zero();
  bool converged = false;
  // The load parameter F l^2 / (E I) of the whole load.
  const double end = count > 0 ? loads[std::size_t(order[std::size_t(count - 1)])].s_m : 0.0;
  const double alpha = MomentScale(loads) * end / EI_;
  // A cold start (the straight rod as the guess) goes straight to the continuation once the
  // load is large: from the straight rod Newton finds looped branches beyond alpha ~ 40, whose
  // end is no further turned than the first mode's; up to 10 it finds the first mode
  // (tests/model/rod_test.cpp).
  const bool cold = end_R_guess.isIdentity(0.0);
  if (end_R_guess.allFinite() && !(cold && alpha > 10.0)) {
    // From the guess: a few iterations, since a guess from the same branch converges in two or
    // three. Newton from far can land on another branch (from the straight rod at
    // F l^2 / (E I) = 60 it finds a looped one in four iterations), so a solution whose end
    // turned more than half a radian from the guess is not taken: a tick's loads change far
    // less than that, and the continuation below decides instead.
    const Eigen::Matrix3d guess = Eigen::Quaterniond(end_R_guess).normalized().toRotationMatrix();
    Q = guess;
    converged = Newton(loads, sorted, 1.0, 8, Q, J_inv, solution.iterations, result, buffers) &&
                Eigen::AngleAxisd(Q * guess.transpose()).angle() <= 0.5;
  }
  // Continuation from the unloaded rod: the load grown in steps, each solved from the last, at
  // first so that each step adds about 2 to the load parameter, then finer.
  const int first_steps = static_cast<int>(std::clamp(std::ceil(alpha / 2.0), 1.0, 64.0));
  // The work is capped (kMaxIterations Newton iterations, ~5 integrations each): a tick must
  // end, and a loading that needs more falls back to the linear model, flagged.
  for (int steps = first_steps; !converged && steps <= 4 * 256; steps *= 4) {
    Q.setIdentity();
    J_inv.setZero();
    converged = true;
    for (int k = 1; k <= steps && converged; ++k)
      converged = solution.iterations < kMaxIterations &&
                  Newton(loads, sorted, double(k) / steps, 20, Q, J_inv, solution.iterations,
                         result, buffers);
  }
  if (!converged && !Q.allFinite()) {
    Q.setIdentity();
    result = Integrate(loads, sorted, 1.0, Q, shape);
  }
  solution.end_R = Q;
  solution.jacobian_inv = converged ? J_inv : Eigen::Matrix3d::Zero();
  solution.root_moment_Nm =
      result.root_moment.allFinite() ? result.root_moment : Eigen::Vector3d::Zero();
  solution.converged = converged && result.residual.allFinite();
  solution.energy_J = std::isfinite(result.energy_J) ? result.energy_J : 0.0;
  solution.max_moment_Nm = std::isfinite(result.max_moment_Nm) ? result.max_moment_Nm : 0.0;
  solution.end_m = end;
  solution.end_p_m = result.end_p.allFinite() ? result.end_p : Eigen::Vector3d(0.0, 0.0, end);
  return solution;
}

RodSolution Rod::SolvePinned(std::span<RodLoad> loads, const RodSolution& start,
                             std::span<const Eigen::Vector2d> pinned_xy_m,
                             const RodSamples& shape) const {
  Order order{};
  const int count = SortedOrder(loads, order);
  const std::span<const int> sorted(order.data(), std::size_t(count));
  RodSolution solution;
  if (count == 0 || pinned_xy_m.size() != std::size_t(count)) return solution;
  const double end = loads[std::size_t(order[std::size_t(count - 1)])].s_m;
  // The loads' arc positions in ascending order: where the centre is pinned (offset zero).
  std::array<double, kMaxLoads> s_sorted{};
  std::array<Eigen::Vector3d, kMaxLoads> zero_r, p;
  for (int k = 0; k < count; ++k) {
    s_sorted[std::size_t(k)] = loads[std::size_t(order[std::size_t(k)])].s_m;
    zero_r[std::size_t(k)].setZero();
  }
  const RodSamples at_loads{std::span<const double>(s_sorted.data(), std::size_t(count)),
                            std::span<Eigen::Vector3d>(p.data(), std::size_t(count)),
                            {}};
  constexpr int kMaxDirections = 3 + 3 * kMaxLoads;
  constexpr int kMaxUnknowns = 3 + 2 * kMaxLoads;
  using Matrix =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxUnknowns, kMaxUnknowns>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxUnknowns, 1>;
  const int unknowns = 3 + 2 * count;
  Tangent<kMaxDirections> tangent;
  tangent.directions = 3 + 3 * count;
  tangent.surface_r_m = std::span<const Eigen::Vector3d>(zero_r.data(), std::size_t(count));
  // The residuals: the root's turn from the clamp [rad], and each pinned centre's miss divided by
  // the end's arc position (so that both are angles).
  Vector residual(unknowns);
  const auto evaluate = [&](std::span<const RodLoad> trial_loads, const Eigen::Matrix3d& Q) {
    const Result r = Integrate(trial_loads, sorted, 1.0, Q, at_loads, &tangent);
    residual.head<3>() = r.residual;
    for (int k = 0; k < count; ++k)
      residual.segment<2>(3 + 2 * k) =
          (p[std::size_t(k)].head<2>() - pinned_xy_m[std::size_t(order[std::size_t(k)])]) / end;
    return residual.allFinite() ? residual.squaredNorm() : std::numeric_limits<double>::infinity();
  };
  std::array<RodLoad, kMaxLoads> now{}, trial{};
  std::copy(loads.begin(), loads.end(), now.begin());
  const std::span<const RodLoad> now_span(now.data(), std::size_t(count));
  const std::span<const RodLoad> trial_span(trial.data(), std::size_t(count));
  const Eigen::Matrix3d start_R = Eigen::Quaterniond(start.end_R).normalized().toRotationMatrix();
  Eigen::Matrix3d Q = start_R;
  double merit = evaluate(now_span, Q);
  Matrix J(unknowns, unknowns);
  // NaN never counts as a small residual (Eigen's largest coefficient passes NaN over).
  const auto small = [&] {
    return residual.allFinite() && residual.lpNorm<Eigen::Infinity>() <= 1e-10;
  };
  bool converged = false;
  int slow = 0;
  for (int it = 0; it < kMaxPinnedIterations && std::isfinite(merit); ++it) {
    ++solution.iterations;
    if (small()) {
      converged = true;
      break;
    }
    // Columns: the end's turn (directions 0-2), then each load's x and y force (3 + 3 j + c); rows
    // as the residuals.
    for (int c = 0; c < unknowns; ++c) {
      const int d = c < 3 ? c : 3 + 3 * ((c - 3) / 2) + (c - 3) % 2;
      J.block<3, 1>(0, c) = tangent.residual[std::size_t(d)];
      for (int k = 0; k < count; ++k)
        J.block<2, 1>(3 + 2 * k, c) =
            tangent.surface[std::size_t(k) * kMaxDirections + std::size_t(d)].head<2>() / end;
    }
    const Eigen::PartialPivLU<Matrix> lu(J);
    Vector step = lu.solve(-residual);
    if (!step.allFinite()) break;
    // At most half a radian of the end's turn a step, as Newton's.
    const double turn = step.head<3>().norm();
    if (turn > 0.5) step *= 0.5 / turn;
    bool improved = false;
    const Vector last = residual;
    const double merit_before = merit;
    for (double lambda = 1.0; lambda > 1.0 / 16.0 && !improved; lambda *= 0.5) {
      std::copy(now.begin(), now.begin() + count, trial.begin());
      for (int j = 0; j < count; ++j)
        trial[std::size_t(j)].f_N.head<2>() += lambda * step.segment<2>(3 + 2 * j);
      const Eigen::Matrix3d Q_trial = Rotation(lambda * step.head<3>()) * Q;
      const double m = evaluate(trial_span, Q_trial);
      if (m < merit) {
        merit = m;
        Q = Q_trial;
        std::copy(trial.begin(), trial.begin() + count, now.begin());
        improved = true;
      }
    }
    if (!improved) {
      residual = last;
      break;
    }
    // Near a solution of this well-posed problem Newton at least halves the residual a step; a
    // second step that does not is not converging from this start, and each costs an integration
    // carrying 3 + 3n directions (a pin that cannot hold, a pinched squeeze's, took up to 1 ms
    // with twelve steps of six halvings): given up.
    if (!(merit <= 0.25 * merit_before) && ++slow == 2) break;
  }
  if (!converged) converged = small();
  // As Solve's: a solution whose end turned more than half a radian from the start is another
  // branch, not the one the start was on.
  if (!converged || Eigen::AngleAxisd(Q * start_R.transpose()).angle() > 0.5) return solution;
  // The shape at the samples, and the figures, from one plain integration at the solution (with
  // the samples as breakpoints: a rod within its discretisation error of the solve's, 2e-8 m at
  // the rubber tube's tip), written to the caller's samples only if finite.
  const std::size_t sample_count = std::min(shape.s_m.size(), std::size_t(kMaxShapeSamples));
  std::array<Eigen::Vector3d, kMaxShapeSamples> drawn_p;
  const Result result = Integrate(
      now_span, sorted, 1.0, Q,
      RodSamples{shape.s_m.first(sample_count), std::span(drawn_p.data(), sample_count), {}});
  bool finite = result.residual.allFinite() && std::isfinite(result.energy_J);
  for (std::size_t k = 0; k < sample_count && finite; ++k) finite = drawn_p[k].allFinite();
  if (!finite) return solution;
  std::copy_n(drawn_p.begin(), sample_count, shape.p_m.begin());
  std::copy(now.begin(), now.begin() + count, loads.begin());
  solution.end_R = Q;
  solution.converged = true;
  solution.root_moment_Nm = result.root_moment;
  solution.energy_J = result.energy_J;
  solution.max_moment_Nm = result.max_moment_Nm;
  solution.end_m = end;
  solution.end_p_m = result.end_p;
  return solution;
}

void Rod::Shape(std::span<const RodLoad> loads, const RodSolution& solution,
                const RodSamples& samples) const {
  Order order{};
  const int count = SortedOrder(loads, order);
  Integrate(loads, std::span<const int>(order.data(), std::size_t(count)), 1.0, solution.end_R,
            samples);
}

bool Rod::Compliance(std::span<const RodLoad> loads, const RodSolution& solution,
                     std::span<Eigen::Matrix3d> w, std::span<Eigen::Matrix3d> end_turn,
                     RodEndMoment* end_moment) const {
  Order order{};
  const int count = SortedOrder(loads, order);
  const std::span<const int> sorted(order.data(), std::size_t(count));
  assert(w.size() >= std::size_t(count * count));
  assert(end_turn.empty() || end_turn.size() >= std::size_t(count));
  // The loads' arc positions in ascending order (the integration's samples) and their offsets.
  std::array<double, kMaxLoads> s_sorted{};
  std::array<Eigen::Vector3d, kMaxLoads> r_sorted;
  for (int k = 0; k < count; ++k) {
    s_sorted[std::size_t(k)] = loads[std::size_t(order[std::size_t(k)])].s_m;
    r_sorted[std::size_t(k)] = loads[std::size_t(order[std::size_t(k)])].r_m;
  }
  std::array<Eigen::Vector3d, kMaxLoads> p;
  const std::span<const double> s_span(s_sorted.data(), std::size_t(count));
  // One integration carries the derivatives along the end's turn q, every force F_j and, if
  // asked for, a moment M on the end section: the surface points S and the clamp residual e
  // move by dS/dq, dS/dF, dS/dM, de/dq, de/dF, de/dM.
  constexpr int kMaxDirections = 6 + 3 * kMaxLoads;
  Tangent<kMaxDirections> tangent;
  const int first_moment = 3 + 3 * count;
  tangent.directions = first_moment + (end_moment != nullptr ? 3 : 0);
  tangent.surface_r_m = std::span<const Eigen::Vector3d>(r_sorted.data(), std::size_t(count));
  Integrate(loads, sorted, 1.0, solution.end_R,
            {s_span, std::span(p.data(), std::size_t(count)), {}}, &tangent);
  Eigen::Matrix3d E_u;
  for (int c = 0; c < 3; ++c) E_u.col(c) = tangent.residual[std::size_t(c)];
  const double det = E_u.determinant();
  if (!(std::abs(det) > 1e-12) || !E_u.allFinite()) return false;
  const Eigen::Matrix3d E_u_inv = E_u.inverse();
  // Direction d's response with the root kept clamped: the end's turn u = -E_u^-1 de/dd, and
  // each surface point's dS/dd + dS/dq u.
  const auto respond = [&](std::size_t d, Eigen::Vector3d& u, const auto& surface_column) {
    u = -E_u_inv * tangent.residual[d];
    for (int ki = 0; ki < count; ++ki) {
      const std::size_t at = std::size_t(ki) * kMaxDirections;
      surface_column(
          order[std::size_t(ki)],
          Eigen::Vector3d(tangent.surface[at + d] + tangent.surface[at + 0] * u.x() +
                          tangent.surface[at + 1] * u.y() + tangent.surface[at + 2] * u.z()));
    }
  };
  for (int j = 0; j < count; ++j)
    for (int c = 0; c < 3; ++c) {
      // The end's turn that keeps the root clamped as F_j moves.
      Eigen::Vector3d u_F;
      respond(std::size_t(3 + 3 * j + c), u_F,
              [&](int i, const Eigen::Vector3d& dS) { w[std::size_t(i * count + j)].col(c) = dS; });
      if (!end_turn.empty()) end_turn[std::size_t(j)].col(c) = u_F;
    }
  for (int k = 0; k < count * count; ++k)
    if (!w[std::size_t(k)].allFinite()) return false;
  for (std::size_t j = 0; j < end_turn.size() && j < std::size_t(count); ++j)
    if (!end_turn[j].allFinite()) return false;
  if (end_moment != nullptr) {
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector3d u_M;
      respond(std::size_t(first_moment + c), u_M, [&](int i, const Eigen::Vector3d& dS) {
        end_moment->w_per_Nm[std::size_t(i)].col(c) = dS;
      });
      end_moment->turn_per_Nm.col(c) = u_M;
    }
    if (!end_moment->turn_per_Nm.allFinite()) return false;
    for (int i = 0; i < count; ++i)
      if (!end_moment->w_per_Nm[std::size_t(i)].allFinite()) return false;
  }
  return true;
}

}  // namespace tubeplan::model
