// The virtual coupling: passive defaults for the device (docs/scene-format.md, "Device").
#include <catch2/catch.hpp>

#include <tubeplan/core/coupling.hpp>

namespace {
using tubeplan::core::Coupling;
using tubeplan::core::IsPassive;
using tubeplan::core::ResolveCoupling;
using tubeplan::scene::Device;
}  // namespace

TEST_CASE("Colgate's condition b > K T / 2 + |B|", "[coupling]") {
  // b = 5 N s/m, T = 1 ms: K up to 10000 N/m with B = 0, up to 6000 N/m with B = 2 N s/m.
  CHECK(IsPassive(5.0, {9999.0, 0.0}, 1e-3));
  CHECK_FALSE(IsPassive(5.0, {10000.0, 0.0}, 1e-3));
  CHECK(IsPassive(5.0, {5999.0, 2.0}, 1e-3));
  CHECK_FALSE(IsPassive(5.0, {6001.0, -2.0}, 1e-3));  // negative damping counts by magnitude
}

TEST_CASE("Default coupling: half of the device's limit and of the passivity bound", "[coupling]") {
  // PHANToM Premium 1.5/6DOF (800 N/m, b = 5 N s/m) at 1 kHz: min(800, 10000) / 2 = 400 N/m.
  const Device premium;
  const Coupling c = ResolveCoupling(premium, 1e-3);
  CHECK(c.stiffness_N_per_m == 400.0);
  CHECK(c.damping_Ns_per_m == 0.0);
  CHECK(IsPassive(premium.damping_Ns_per_m, c, 1e-3));
  // A lightly damped device at a slow rate: passivity binds, 2 * 0.2 / 0.01 = 40, half is 20.
  Device slow;
  slow.damping_Ns_per_m = 0.2;
  CHECK(ResolveCoupling(slow, 0.01).stiffness_N_per_m == Approx(20.0).epsilon(1e-15));
  CHECK(IsPassive(slow.damping_Ns_per_m, ResolveCoupling(slow, 0.01), 0.01));
  // Coupling damping at or above the device's: no positive passive stiffness.
  Device over;
  over.coupling_damping_Ns_per_m = 5.0;
  CHECK(ResolveCoupling(over, 1e-3).stiffness_N_per_m == 0.0);
}

TEST_CASE("A scene's own coupling is used as given", "[coupling]") {
  Device d;
  d.coupling_stiffness_N_per_m = 300.0;
  d.coupling_damping_Ns_per_m = 2.0;
  const Coupling c = ResolveCoupling(d, 1e-3);
  CHECK(c.stiffness_N_per_m == 300.0);
  CHECK(c.damping_Ns_per_m == 2.0);
}
