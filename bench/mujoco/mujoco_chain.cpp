// The tube as a MuJoCo 2.2.2 chain (bench/mujoco/mujoco_chain.hpp). The mapping, per element of
// length h = l / N:
// - bending: a ball joint at each element's start, stiffness EI / h (the discrete rod's
//   (EI/h)(1 - cos phi) to second order); the joint at the grip 2 EI / h, the first element
//   turning from the grip's axis over half an element as in tubeplan's rod (docs/core.md);
// - damping: each joint's damping its stiffness times 2 / omega_1, omega_1 the chain's first
//   bending mode as a clamped beam: that mode critically damped, the higher ones more;
//   MuJoCo's Euler integrator takes joint damping implicitly;
// - the end: the last element a cylinder, so the end is flat as tubeplan's (its rim, not a
//   capsule's round cap, touches the floor);
// - contact: the plane with margin epsilon (a force from distance epsilon on, as K (eps - d)+),
//   impedance fixed at 0.9 and a stiffness calibrated so that normal force / (margin - distance)
//   is K; with friction, an elliptic cone and the no-slip solver, so that a stuck end does not
//   creep; without, normal force only (condim 1).
#include "mujoco_chain.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mujoco/mujoco.h>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench.hpp"

namespace tubeplan::bench::mujoco {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// MuJoCo's constant impedance (solimp d0 = dmax): the share of the contact's force that follows
// its reference acceleration.
constexpr double kImpedance = 0.9;
// No-slip solver iterations after the main solve (MuJoCo's soft friction otherwise lets a stuck
// contact creep at a speed proportional to its force).
constexpr int kNoSlipIterations = 20;

// The numbers the XML is written from.
struct ChainSettings {
  int elements = 0;
  int steps_per_ms = 1;
  double contact_k = 0.0;  // solref's direct stiffness (MuJoCo's units: acceleration per metre)
  double contact_b = 0.0;  // and damping (acceleration per m/s)
};

std::string ChainXml(const ChainCase& c, const ChainSettings& s, const Eigen::Isometry3d& X_grip) {
  const int n = s.elements;
  const double h = c.length_m / n, r1 = c.outer_radius_m, r2 = c.inner_radius_m;
  const double area = std::numbers::pi * (r1 * r1 - r2 * r2);
  const double mass = c.density_kg_per_m3 * area * h;
  const double i_axial = 0.5 * mass * (r1 * r1 + r2 * r2);
  const double i_lateral = mass * (3.0 * (r1 * r1 + r2 * r2) + h * h) / 12.0;
  // The clamped beam's first mode: omega_1 = 1.875^2 sqrt(EI / (rho A l^4)).
  const double omega_1 =
      1.875104 * 1.875104 *
      std::sqrt(c.bending_stiffness_Nm2 / (c.density_kg_per_m3 * area * std::pow(c.length_m, 4)));
  const double damping_time_s = 2.0 / omega_1;
  const double k_joint = c.bending_stiffness_Nm2 / h;
  const Eigen::Quaterniond q(X_grip.linear());
  const Eigen::Vector3d p = X_grip.translation();
  std::ostringstream x;
  x.precision(17);
  x << "<mujoco model=\"tube\">\n"
    << "  <option timestep=\"" << 1e-3 / s.steps_per_ms
    << "\" gravity=\"0 0 0\" integrator=\"Euler\" cone=\"elliptic\" noslip_iterations=\""
    << (c.friction > 0.0 ? kNoSlipIterations : 0) << "\"/>\n"
    << "  <size njmax=\"200\" nconmax=\"40\"/>\n"
    << "  <default><geom contype=\"1\" conaffinity=\"0\" condim=\"" << (c.friction > 0.0 ? 3 : 1)
    << "\" margin=\"" << c.threshold_m << "\" friction=\"" << (c.friction > 0.0 ? c.friction : 1.0)
    << " 0 0\" solref=\"" << -s.contact_k << ' ' << -s.contact_b << "\" solimp=\"" << kImpedance
    << ' ' << kImpedance << " 0.001 0.5 2\"/></default>\n"
    << "  <worldbody>\n"
    << "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\" pos=\"0 0 " << c.floor_z_m
    << "\" contype=\"0\" conaffinity=\"1\"/>\n"
    << "    <body name=\"grip\" mocap=\"true\" pos=\"" << p.x() << ' ' << p.y() << ' ' << p.z()
    << "\" quat=\"" << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << "\">\n";
  for (int i = 0; i < n; ++i) {
    x << "<body name=\"e" << i << "\" pos=\"0 0 " << (i == 0 ? 0.0 : h) << "\">"
      << "<joint type=\"ball\" stiffness=\"" << (i == 0 ? 2.0 : 1.0) * k_joint << "\" damping=\""
      << (i == 0 ? 2.0 : 1.0) * k_joint * damping_time_s << "\"/>"
      << "<inertial pos=\"0 0 " << 0.5 * h << "\" mass=\"" << mass << "\" diaginertia=\""
      << i_lateral << ' ' << i_lateral << ' ' << i_axial << "\"/>"
      << "<geom type=\"" << (i + 1 < n ? "capsule" : "cylinder") << "\" fromto=\"0 0 0 0 0 " << h
      << "\" size=\"" << r1 << "\"/>\n";
  }
  for (int i = 0; i < n; ++i) x << "</body>";
  x << "\n    </body>\n  </worldbody>\n</mujoco>\n";
  return x.str();
}

ModelPtr Load(const std::string& xml) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "tube.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, int(xml.size())) != 0)
    throw std::runtime_error("MuJoCo's virtual file system refused the chain's XML");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name)], xml.data(), xml.size());
  char error[1000] = "";
  ModelPtr m(mj_loadXML(name, vfs.get(), error, sizeof error));
  mj_deleteFileVFS(vfs.get(), name);
  if (!m) throw std::runtime_error(std::string("MuJoCo did not load the chain: ") + error);
  return m;
}

struct Sim {
  ModelPtr m;
  DataPtr d;
  int first = 0, last = 0;  // the first and last element's bodies
  double h = 0.0;
};

Sim MakeSim(const ChainCase& c, const ChainSettings& s) {
  Sim sim;
  sim.m = Load(ChainXml(c, s, c.hand(0.0)));
  sim.d.reset(mj_makeData(sim.m.get()));
  if (!sim.d) throw std::runtime_error("MuJoCo could not allocate its data");
  sim.first = mj_name2id(sim.m.get(), mjOBJ_BODY, "e0");
  sim.last = mj_name2id(sim.m.get(), mjOBJ_BODY, ("e" + std::to_string(s.elements - 1)).c_str());
  sim.h = c.length_m / s.elements;
  return sim;
}

void SetGrip(Sim& sim, const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  for (int k = 0; k < 3; ++k) sim.d->mocap_pos[k] = X.translation()[k];
  sim.d->mocap_quat[0] = q.w();
  sim.d->mocap_quat[1] = q.x();
  sim.d->mocap_quat[2] = q.y();
  sim.d->mocap_quat[3] = q.z();
}

// The centre of the end face [m].
Eigen::Vector3d Tip(const Sim& sim) {
  const mjtNum* R = sim.d->xmat + 9 * sim.last;
  const mjtNum* p = sim.d->xpos + 3 * sim.last;
  return {p[0] + R[2] * sim.h, p[1] + R[5] * sim.h, p[2] + R[8] * sim.h};
}

// The forces at this state (positions and velocities as they are).
struct Forces {
  double grip_z_N = 0.0, contact_z_N = 0.0, stiffness_N_per_m = 0.0;
  int contacts = 0;
};

Forces Read(Sim& sim) {
  mjModel* m = sim.m.get();
  mjData* d = sim.d.get();
  mj_forward(m, d);
  mj_rnePostConstraint(m, d);
  Forces f;
  // The grip's force on the first element (cfrc_int's last three: the force from the parent);
  // the operator feels its opposite.
  f.grip_z_N = -d->cfrc_int[6 * sim.first + 5];
  double normal_N = 0.0, depth_m = 0.0;
  for (int i = 0; i < d->ncon; ++i) {
    mjtNum local[6];
    mj_contactForce(m, d, i, local);
    const mjContact& con = d->contact[i];
    // The frame's rows are the normal (from the floor, geom1, into the chain) and two tangents.
    for (int r = 0; r < 3; ++r) f.contact_z_N += local[r] * con.frame[3 * r + 2];
    normal_N += local[0];
    depth_m = std::max(depth_m, con.includemargin - con.dist);
    ++f.contacts;
  }
  f.stiffness_N_per_m = depth_m > 0.0 ? normal_N / depth_m : 0.0;
  return f;
}

bool Finite(const Sim& sim) {
  for (int i = 0; i < sim.m->nq; ++i)
    if (!std::isfinite(sim.d->qpos[i])) return false;
  for (int i = 0; i < sim.m->nv; ++i)
    if (!std::isfinite(sim.d->qvel[i])) return false;
  for (int w = 0; w < mjNWARNING; ++w)
    if (sim.d->warning[w].number > 0) return false;
  return true;
}

// The approach and settling: the grip along the hand's path for c.settle_s; stable when every
// number stayed finite without MuJoCo's warnings and the force changed by less than 0.01 % over
// the last 100 ms.
struct Settled {
  bool stable = false;
  Forces forces;
};

Settled Settle(Sim& sim, const ChainCase& c, int steps_per_ms) {
  Settled out;
  const int ms = int(std::lround(c.settle_s * 1e3));
  double earlier_z_N = 0.0;
  for (int k = 0; k < ms; ++k) {
    for (int j = 0; j < steps_per_ms; ++j) {
      SetGrip(sim, c.hand(sim.d->time));
      mj_step(sim.m.get(), sim.d.get());
    }
    if (!Finite(sim)) return out;
    if (k == ms - 100) earlier_z_N = Read(sim).grip_z_N;
  }
  out.forces = Read(sim);
  out.stable = Finite(sim) &&
               std::abs(out.forces.grip_z_N - earlier_z_N) <= 1e-4 * std::abs(out.forces.grip_z_N);
  return out;
}

// One simulated ms from the state `sim` is in, the grip at X.
double SimulatedMs(Sim& sim, int steps_per_ms, const Eigen::Isometry3d& X) {
  SetGrip(sim, X);
  for (int j = 0; j < steps_per_ms; ++j) mj_step(sim.m.get(), sim.d.get());
  return sim.d->qpos[0];
}

// The longest stable time step dividing 1 ms whose settled force agrees with the next shorter
// one's to 0.2 %, with the contact's stiffness calibrated at it.
ChainSettings StableSettings(const ChainCase& c, int elements) {
  const std::vector<int> steps_per_ms = {1, 2, 4, 5, 8, 10, 16, 20, 25, 40, 50, 80, 100, 200};
  ChainSettings s;
  s.elements = elements;
  std::optional<std::pair<ChainSettings, double>> coarser;  // a stable step and its force
  for (const int steps : steps_per_ms) {
    s.steps_per_ms = steps;
    if (s.contact_k == 0.0) {
      // A first guess: MuJoCo's static contact stiffness is k d^2 / ((1 - d) w), w its estimate
      // of the contact's inverse inertia (the body's body_invweight0).
      const Sim probe = MakeSim(c, s);
      const double w = probe.m->body_invweight0[2 * probe.last];
      s.contact_k =
          c.contact_stiffness_N_per_m * (1.0 - kImpedance) * w / (kImpedance * kImpedance);
    }
    s.contact_b = 2.0 * std::sqrt(s.contact_k);
    Sim sim = MakeSim(c, s);
    Settled settled = Settle(sim, c, steps);
    // The force is proportional to the stiffness at a given depth: scaled once to K.
    const double scale = settled.stable && settled.forces.stiffness_N_per_m > 0.0
                             ? c.contact_stiffness_N_per_m / settled.forces.stiffness_N_per_m
                             : 1.0;
    if (std::abs(scale - 1.0) > 1e-3) {
      s.contact_k *= scale;
      s.contact_b = 2.0 * std::sqrt(s.contact_k);
      sim = MakeSim(c, s);
      settled = Settle(sim, c, steps);
    }
    std::fprintf(stderr, "  MuJoCo, %2d elements, %3d steps/ms: %s, force %.6g N, K %.5g N/m\n",
                 elements, steps, settled.stable ? "settled" : "unstable", settled.forces.grip_z_N,
                 settled.forces.stiffness_N_per_m);
    if (!settled.stable) {
      coarser.reset();
      continue;
    }
    if (coarser && std::abs(coarser->second - settled.forces.grip_z_N) <=
                       2e-3 * std::abs(settled.forces.grip_z_N))
      return coarser->first;
    coarser = {s, settled.forces.grip_z_N};
  }
  throw std::runtime_error("MuJoCo found no stable time step for " + std::to_string(elements) +
                           " elements down to 5 us");
}

}  // namespace

ChainRun RunChain(const ChainCase& c, int elements, int samples) {
  const ChainSettings s = StableSettings(c, elements);
  Sim sim = MakeSim(c, s);
  const Settled settled = Settle(sim, c, s.steps_per_ms);
  ChainRun run;
  run.elements = elements;
  run.steps_per_ms = s.steps_per_ms;
  run.force_z_N = settled.forces.grip_z_N;
  run.contact_force_z_N = settled.forces.contact_z_N;
  run.contact_stiffness_N_per_m = settled.forces.stiffness_N_per_m;
  run.contacts = settled.forces.contacts;
  // Timed as `tubeplan bench` times a tick (bench::Measure): one sample a simulated ms.
  const Eigen::Isometry3d X_held = c.hand(sim.d->time);
  const Eigen::Vector3d tip_before = Tip(sim);
  double sink = 0.0;
  Scenario still{"mujoco.still", "the hand held still", 1, 0.0,
                 [&](int) { return SimulatedMs(sim, s.steps_per_ms, X_held); }};
  run.still_us = 1e6 * Measure(still, samples, sink).median_s;
  run.tip_drift_m = (Tip(sim) - tip_before).head<2>().norm();
  long ms = 0;
  Scenario dithered{"mujoco.dithered", "the hand dithered", 1, 0.0,
                    [&](int) { return SimulatedMs(sim, s.steps_per_ms, Dither(X_held, ms++)); }};
  run.dithered_us = 1e6 * Measure(dithered, samples, sink).median_s;
  if (!std::isfinite(sink)) throw std::runtime_error("MuJoCo's state went non-finite while timed");
  return run;
}

}  // namespace tubeplan::bench::mujoco
