#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include <tubeplan/trajectories/perturb.hpp>

namespace tubeplan::trajectories {

Trajectory Perturb(const Trajectory& trajectory, const Perturbation& p, std::uint64_t seed,
                   int replicate) {
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         static_cast<std::uint32_t>(replicate)};
  std::mt19937_64 rng(sequence);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Offset: uniform in the ball (direction uniform on the sphere, radius r cbrt(u)).
  const double z = 2.0 * unit(rng) - 1.0, phi = 2.0 * std::numbers::pi * unit(rng);
  const double radius = p.offset_m * std::cbrt(unit(rng));
  const Eigen::Vector3d offset = radius * Eigen::Vector3d(std::sqrt(1 - z * z) * std::cos(phi),
                                                          std::sqrt(1 - z * z) * std::sin(phi), z);
  std::array<double, 3> frequency{}, phase{};
  for (int axis = 0; axis < 3; ++axis) {
    frequency[std::size_t(axis)] = 8.0 + 4.0 * unit(rng);
    phase[std::size_t(axis)] = 2.0 * std::numbers::pi * unit(rng);
  }
  const double speed = p.speed_min + (p.speed_max - p.speed_min) * unit(rng);
  Trajectory out = trajectory;
  const double t0 = trajectory.samples.front().t_s;
  for (HandSample& s : out.samples) {
    s.t_s = t0 + (s.t_s - t0) / speed;
    s.p_WH_m += offset;
    for (int axis = 0; axis < 3; ++axis) {
      s.p_WH_m[axis] +=
          p.tremor_m * std::sin(2.0 * std::numbers::pi * frequency[std::size_t(axis)] * s.t_s +
                                phase[std::size_t(axis)]);
    }
  }
  return out;
}

Interval WilsonInterval(int successes, int trials) {
  const double n = trials, phat = successes / n, z = 1.96;
  const double centre = (phat + z * z / (2 * n)) / (1 + z * z / n);
  const double half = z / (1 + z * z / n) * std::sqrt(phat * (1 - phat) / n + z * z / (4 * n * n));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

}  // namespace tubeplan::trajectories
