#include "core/rod.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace tubeplan::core {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

// (I - a a^T) / length: the derivative of a unit vector a = v / |v| with respect to v.
Mat3 UnitDerivative(const Vec3& a, double length) {
  return (Mat3::Identity() - a * a.transpose()) / length;
}

// Maps a Hessian over the element vectors (e, f) = (x1 - x0, x2 - x1) to the three nodes.
void EdgesToNodes(const Mat3& hee, const Mat3& hef, const Mat3& hff, const Vec3& ge, const Vec3& gf,
                  StencilTerm& term) {
  term.nodes = 3;
  term.gradient.segment<3>(0) = -ge;
  term.gradient.segment<3>(3) = ge - gf;
  term.gradient.segment<3>(6) = gf;
  const Mat3 hfe = hef.transpose();
  auto H = [&](int r, int c) { return term.hessian.block<3, 3>(3 * r, 3 * c); };
  H(0, 0) = hee;
  H(0, 1) = -hee + hef;
  H(0, 2) = -hef;
  H(1, 1) = hee - hef - hfe + hff;
  H(1, 2) = hef - hff;
  H(2, 2) = hff;
  H(1, 0) = (-hee + hef).transpose();
  H(2, 0) = -hfe;
  H(2, 1) = (hef - hff).transpose();
}

}  // namespace

double BendingEnergy(const RodModel& rod, const Vec3& t_H, std::span<const Vec3> x_W, int i,
                     StencilTerm* term) {
  if (i == 0) {
    // Between the grip's axis and the first element.
    const double c = 2.0 * rod.bending_stiffness_Nm2 / rod.segment_m;
    const Vec3 f = x_W[1] - x_W[0];
    const double lf = f.norm();
    const Vec3 b = f / lf;
    const double cos_phi = t_H.dot(b);
    if (term != nullptr) {
      const Vec3 gf = (t_H - cos_phi * b) / lf;
      const Mat3 H = -c * (-(b * gf.transpose() + gf * b.transpose()) / lf -
                           cos_phi * (Mat3::Identity() - b * b.transpose()) / (lf * lf));
      term->first = 0;
      term->nodes = 2;
      term->gradient.segment<3>(0) = c * gf;
      term->gradient.segment<3>(3) = -c * gf;
      term->hessian.block<3, 3>(0, 0) = H;
      term->hessian.block<3, 3>(3, 3) = H;
      term->hessian.block<3, 3>(0, 3) = -H;
      term->hessian.block<3, 3>(3, 0) = -H;
    }
    // 1 - cos phi as |t - b|^2 / 2: no cancellation when the angle is small.
    return 0.5 * c * (t_H - b).squaredNorm();
  }
  const double c = rod.bending_stiffness_Nm2 / rod.segment_m;
  const Vec3 e = x_W[std::size_t(i)] - x_W[std::size_t(i - 1)];
  const Vec3 f = x_W[std::size_t(i + 1)] - x_W[std::size_t(i)];
  const double le = e.norm(), lf = f.norm();
  const Vec3 a = e / le, b = f / lf;
  const double cos_phi = a.dot(b);
  if (term != nullptr) {
    // E = c (1 - a.b); with g_e = d(a.b)/de = (b - cos a) / |e| and likewise g_f:
    const Vec3 ge = (b - cos_phi * a) / le, gf = (a - cos_phi * b) / lf;
    if (!term->with_hessian) {
      term->first = i - 1;
      term->nodes = 3;
      term->gradient.segment<3>(0) = c * ge;
      term->gradient.segment<3>(3) = c * (gf - ge);
      term->gradient.segment<3>(6) = -c * gf;
      return 0.5 * c * (a - b).squaredNorm();
    }
    const Mat3 I = Mat3::Identity();
    const Mat3 dge_de = -(a * ge.transpose() + ge * a.transpose()) / le -
                        cos_phi * (I - a * a.transpose()) / (le * le);
    const Mat3 dgf_df = -(b * gf.transpose() + gf * b.transpose()) / lf -
                        cos_phi * (I - b * b.transpose()) / (lf * lf);
    const Mat3 dge_df = ((I - b * b.transpose()) / lf - a * gf.transpose()) / le;
    term->first = i - 1;
    EdgesToNodes(-c * dge_de, -c * dge_df, -c * dgf_df, -c * ge, -c * gf, *term);
  }
  // 1 - cos phi as |a - b|^2 / 2: no cancellation when the angle is small.
  return 0.5 * c * (a - b).squaredNorm();
}

double StretchEnergy(const RodModel& rod, std::span<const Vec3> x_W, int i, StencilTerm* term) {
  const double k = rod.stretch_stiffness_N / rod.segment_m;
  const Vec3 e = x_W[std::size_t(i + 1)] - x_W[std::size_t(i)];
  const double len = e.norm();
  const double strain_m = len - rod.segment_m;
  if (term != nullptr) {
    const Vec3 a = e / len;
    const Vec3 g = k * strain_m * a;
    const Mat3 aa = a * a.transpose();
    const Mat3 h = k * (aa + (1.0 - rod.segment_m / len) * (Mat3::Identity() - aa));
    term->first = i;
    term->nodes = 2;
    term->gradient.segment<3>(0) = -g;
    term->gradient.segment<3>(3) = g;
    term->hessian.block<3, 3>(0, 0) = h;
    term->hessian.block<3, 3>(3, 3) = h;
    term->hessian.block<3, 3>(0, 3) = -h;
    term->hessian.block<3, 3>(3, 0) = -h;
  }
  return 0.5 * k * strain_m * strain_m;
}

double LinearBendingEnergy(const RodModel& rod, const Mat3& R_WH, std::span<const Vec3> x_W, int i,
                           StencilTerm* term) {
  const double h = rod.segment_m;
  const double c = rod.bending_stiffness_Nm2 / (h * h * h);
  // Lateral projector of the held frame: the beam bends in its x and y only.
  const Vec3 z = R_WH.col(2);
  const Mat3 P = Mat3::Identity() - z * z.transpose();
  if (i == 0) {
    // At the grip: the ghost node x_0 - h z mirrors the clamp.
    const Vec3 b = P * (x_W[1] - x_W[0]);
    if (term != nullptr) {
      term->first = 0;
      term->nodes = 2;
      term->gradient.segment<3>(0) = -2.0 * c * b;
      term->gradient.segment<3>(3) = 2.0 * c * b;
      term->hessian.block<3, 3>(0, 0) = 2.0 * c * P;
      term->hessian.block<3, 3>(3, 3) = 2.0 * c * P;
      term->hessian.block<3, 3>(0, 3) = -2.0 * c * P;
      term->hessian.block<3, 3>(3, 0) = -2.0 * c * P;
    }
    return c * b.squaredNorm();
  }
  const Vec3 b =
      P * (x_W[std::size_t(i + 1)] - 2.0 * x_W[std::size_t(i)] + x_W[std::size_t(i - 1)]);
  if (term != nullptr) {
    term->first = i - 1;
    term->nodes = 3;
    const double w[3] = {1.0, -2.0, 1.0};
    for (int r = 0; r < 3; ++r) {
      term->gradient.segment<3>(3 * r) = c * w[r] * b;
      for (int s = 0; s < 3; ++s) term->hessian.block<3, 3>(3 * r, 3 * s) = c * w[r] * w[s] * P;
    }
  }
  return 0.5 * c * b.squaredNorm();
}

double AxialHoldEnergy(const RodModel& rod, const Mat3& R_WH, std::span<const Vec3> x_W, int i,
                       StencilTerm* term) {
  // Element i's length along the held axis, held at h by the rod's axial stiffness.
  const double k = rod.stretch_stiffness_N / rod.segment_m;
  const Vec3 z = R_WH.col(2);
  const double s = (x_W[std::size_t(i + 1)] - x_W[std::size_t(i)]).dot(z) - rod.segment_m;
  if (term != nullptr) {
    const Mat3 h = k * z * z.transpose();
    term->first = i;
    term->nodes = 2;
    term->gradient.segment<3>(0) = -k * s * z;
    term->gradient.segment<3>(3) = k * s * z;
    term->hessian.block<3, 3>(0, 0) = h;
    term->hessian.block<3, 3>(3, 3) = h;
    term->hessian.block<3, 3>(0, 3) = -h;
    term->hessian.block<3, 3>(3, 0) = -h;
  }
  return 0.5 * k * s * s;
}

std::array<double, 3> CurveWeights(double theta) {
  return {0.5 * (1.0 - theta) * (1.0 - theta), 0.5 + theta - theta * theta, 0.5 * theta * theta};
}

std::array<double, 3> CurveSlopes(double theta) { return {theta - 1.0, 1.0 - 2.0 * theta, theta}; }

Vec3 CarrierTangent(Carrier carrier, std::span<const Vec3> x_W, int i) {
  switch (carrier) {
    case Carrier::kInnerNode:
    case Carrier::kCurve: {
      const Vec3 a = (x_W[std::size_t(i)] - x_W[std::size_t(i - 1)]).normalized();
      const Vec3 b = (x_W[std::size_t(i + 1)] - x_W[std::size_t(i)]).normalized();
      return (a + b).normalized();
    }
    case Carrier::kEndNode:
      return (x_W[std::size_t(i)] - x_W[std::size_t(i - 1)]).normalized();
    case Carrier::kElement:
      return (x_W[std::size_t(i + 1)] - x_W[std::size_t(i)]).normalized();
  }
  return Vec3::UnitZ();
}

Vec3 CarrierCentre(Carrier carrier, std::span<const Vec3> x_W, int i, double theta) {
  if (carrier == Carrier::kElement)
    return x_W[std::size_t(i)] + theta * (x_W[std::size_t(i + 1)] - x_W[std::size_t(i)]);
  if (carrier == Carrier::kCurve) {
    const std::array<double, 3> w = CurveWeights(theta);
    return w[0] * x_W[std::size_t(i - 1)] + w[1] * x_W[std::size_t(i)] +
           w[2] * x_W[std::size_t(i + 1)];
  }
  return x_W[std::size_t(i)];
}

Eigen::Matrix<double, 3, 9> TangentJacobian(Carrier carrier, std::span<const Vec3> x_W, int i) {
  Eigen::Matrix<double, 3, 9> dt = Eigen::Matrix<double, 3, 9>::Zero();
  switch (carrier) {
    case Carrier::kInnerNode:
    case Carrier::kCurve: {
      const Vec3 e = x_W[std::size_t(i)] - x_W[std::size_t(i - 1)];
      const Vec3 f = x_W[std::size_t(i + 1)] - x_W[std::size_t(i)];
      const double le = e.norm(), lf = f.norm();
      const Vec3 a = e / le, b = f / lf;
      const Vec3 s = a + b;
      const double ls = s.norm();
      const Mat3 Pt = UnitDerivative(s / ls, ls);
      const Mat3 Ea = UnitDerivative(a, le), Eb = UnitDerivative(b, lf);
      dt.block<3, 3>(0, 0) = -Pt * Ea;
      dt.block<3, 3>(0, 3) = Pt * (Ea - Eb);
      dt.block<3, 3>(0, 6) = Pt * Eb;
      break;
    }
    case Carrier::kEndNode:
    case Carrier::kElement: {
      const int a = carrier == Carrier::kEndNode ? i - 1 : i;
      const Vec3 e = x_W[std::size_t(a + 1)] - x_W[std::size_t(a)];
      const double le = e.norm();
      const Mat3 E = UnitDerivative(e / le, le);
      dt.block<3, 3>(0, 0) = -E;
      dt.block<3, 3>(0, 3) = E;
      break;
    }
  }
  return dt;
}

void NodeTangents::Resize(int nodes) { entries_.assign(std::size_t(nodes), Entry{}); }

NodeTangents::Entry& NodeTangents::At(std::span<const Vec3> x_W, int i) {
  Entry& e = entries_[std::size_t(i)];
  // Bit for bit the same nodes (x_W is contiguous): a -0 or a NaN is a different input.
  const Vec3* nodes = &x_W[std::size_t(i - 1)];
  if (std::memcmp(nodes, e.nodes_W.data(), sizeof e.nodes_W) != 0) {
    std::copy(nodes, nodes + 3, e.nodes_W.begin());
    e.has_tangent = e.has_jacobian = false;
  }
  return e;
}

const Vec3& NodeTangents::Tangent(std::span<const Vec3> x_W, int i) {
  Entry& e = At(x_W, i);
  if (!e.has_tangent) {
    e.tangent_W = CarrierTangent(Carrier::kInnerNode, x_W, i);
    e.has_tangent = true;
  }
  return e.tangent_W;
}

const Eigen::Matrix<double, 3, 9>& NodeTangents::Jacobian(std::span<const Vec3> x_W, int i) {
  Entry& e = At(x_W, i);
  if (!e.has_jacobian) {
    e.jacobian = TangentJacobian(Carrier::kInnerNode, x_W, i);
    e.has_jacobian = true;
  }
  return e.jacobian;
}

MaterialPoint Material(Carrier carrier, std::span<const Vec3> x_W, int i, double theta,
                       const Vec3& offset0_W, bool jacobian, NodeTangents* tangents) {
  // kCurve's offset turns with node i's tangent, as kInnerNode's does.
  const bool kept =
      tangents != nullptr && (carrier == Carrier::kInnerNode || carrier == Carrier::kCurve);
  // The offset turned with the section: its part along the new tangent removed, length kept,
  // o = |o0| v / |v| with v = (I - t t^T) o0.
  MaterialPoint mp;
  mp.point_W = CarrierCentre(carrier, x_W, i, theta);
  const double l0 = offset0_W.norm();
  // A point on the centre line has no offset to turn.
  const Vec3 t = !(l0 > 0.0) ? Vec3::Zero()
                 : kept      ? tangents->Tangent(x_W, i)
                             : CarrierTangent(carrier, x_W, i);
  const Vec3 v = offset0_W - offset0_W.dot(t) * t;
  const double lv = v.norm();
  mp.tangent_W = t;
  mp.offset_W = lv > 0.0 ? Vec3(v * (l0 / lv)) : Vec3::Zero();
  mp.point_W += mp.offset_W;
  if (!jacobian) return mp;
  // d point / d x_k: a point on the centre line moves with the centre's nodes alone; an offset
  // also turns with the tangent, whose stencil starts one node before a node's.
  const bool turns = lv > 0.0;
  std::array<double, 3> dc{0.0, 1.0, 0.0};
  if (carrier == Carrier::kElement) {
    mp.first = i;
    mp.nodes = 2;
    dc = {1.0 - theta, theta, 0.0};
  } else if (carrier == Carrier::kCurve) {
    mp.first = i - 1;
    mp.nodes = 3;
    dc = CurveWeights(theta);
  } else if (!turns) {
    mp.first = i;
    mp.nodes = 1;
    dc = {1.0, 0.0, 0.0};
  } else {
    mp.first = i - 1;
    mp.nodes = carrier == Carrier::kInnerNode ? 3 : 2;
  }
  for (int k = 0; k < mp.nodes; ++k)
    mp.jacobian.block<3, 3>(0, 3 * k) = dc[std::size_t(k)] * Mat3::Identity();
  if (!turns) return mp;
  // The offset's exact derivative through the tangent's: d o / d t = -(|o0| / |v|) (I - vh vh^T)
  // ((t . o0) I + t o0^T), vh = v / |v|, of which (I - vh vh^T) t = t.
  const Vec3 vh = v / lv;
  const Mat3 across = Mat3::Identity() - vh * vh.transpose();
  const Mat3 do_dt = -(l0 / lv) * (t.dot(offset0_W) * across + t * offset0_W.transpose());
  if (kept)
    mp.jacobian.noalias() += do_dt * tangents->Jacobian(x_W, i);
  else
    mp.jacobian.noalias() += do_dt * TangentJacobian(carrier, x_W, i);
  return mp;
}

}  // namespace tubeplan::core
