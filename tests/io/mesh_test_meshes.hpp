#pragma once
// Small meshes written as files for the mesh tests: a unit cube with named faces (OBJ), the same
// as ASCII and binary STL, prisms extruded from a profile (a 64-sided cylinder, an L).

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tubeplan::testing {

/// The unit cube [0,1]^3: corner i at (i&1, i&2, i&4); its faces in the order of
/// scene::BoxFace (top, bottom, xpos, xneg, ypos, yneg), each counter-clockwise from outside.
inline const std::array<const char*, 6> kCubeFaceNames = {"top",  "bottom", "xpos",
                                                          "xneg", "ypos",   "yneg"};
inline const std::array<std::array<int, 4>, 6> kCubeFaces = {{
    {4, 5, 7, 6},  // top, z = 1
    {0, 2, 3, 1},  // bottom
    {1, 3, 7, 5},  // xpos
    {0, 4, 6, 2},  // xneg
    {2, 6, 7, 3},  // ypos
    {0, 1, 5, 4},  // yneg
}};

inline Eigen::Vector3d CubeCorner(int i) {
  return {double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1)};
}

/// The cube as OBJ: 8 `v` lines (lines 1-8), a comment, then per face a `g` line and an `f` quad
/// (the face of kCubeFaces[k] on line 11 + 2k). `skip` leaves a face out, `flip` reverses one,
/// `reverse` all.
inline std::string CubeObj(int skip = -1, int flip = -1, bool reverse = false,
                           const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  std::ostringstream obj;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p = CubeCorner(i) + offset;
    obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  obj << "# faces\n";
  for (int k = 0; k < 6; ++k) {
    obj << "g " << kCubeFaceNames[std::size_t(k)] << "\n";
    if (k == skip) {
      obj << "# left out\n";
      continue;
    }
    std::array<int, 4> f = kCubeFaces[std::size_t(k)];
    if (k == flip || reverse) std::swap(f[1], f[3]);
    obj << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << " " << f[3] + 1 << "\n";
  }
  return obj.str();
}

/// The cube's 12 triangles: each face's quad as the fan OBJ makes of it.
inline std::vector<std::array<Eigen::Vector3d, 3>> CubeTriangles() {
  std::vector<std::array<Eigen::Vector3d, 3>> out;
  for (const std::array<int, 4>& f : kCubeFaces)
    for (int k = 1; k <= 2; ++k)
      out.push_back(
          {CubeCorner(f[0]), CubeCorner(f[std::size_t(k)]), CubeCorner(f[std::size_t(k + 1)])});
  return out;
}

inline std::string AsciiStl(const std::vector<std::array<Eigen::Vector3d, 3>>& triangles) {
  std::ostringstream stl;
  stl << "solid\n";
  for (const auto& t : triangles) {
    const Eigen::Vector3d n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    stl << "  facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n    outer loop\n";
    for (const Eigen::Vector3d& v : t)
      stl << "      vertex " << v.x() << " " << v.y() << " " << v.z() << "\n";
    stl << "    endloop\n  endfacet\n";
  }
  stl << "endsolid\n";
  return stl.str();
}

/// Binary STL; its 80-byte header starts with "solid", as some exporters write it.
inline std::string BinaryStl(const std::vector<std::array<Eigen::Vector3d, 3>>& triangles) {
  std::string bytes(84 + 50 * triangles.size(), '\0');
  const std::string header = "solid written by the tests, yet binary";
  std::memcpy(bytes.data(), header.data(), header.size());
  const auto count = static_cast<std::uint32_t>(triangles.size());
  for (int b = 0; b < 4; ++b) bytes[std::size_t(80 + b)] = char((count >> (8 * b)) & 0xff);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Vector3d n =
        (triangles[t][1] - triangles[t][0]).cross(triangles[t][2] - triangles[t][0]).normalized();
    std::array<float, 12> values{};
    for (int k = 0; k < 3; ++k) values[std::size_t(k)] = float(n[k]);
    for (std::size_t c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) values[3 + 3 * c + std::size_t(k)] = float(triangles[t][c][k]);
    std::memcpy(bytes.data() + 84 + 50 * t, values.data(), 48);
  }
  return bytes;
}

/// A prism: the counter-clockwise polygon `profile` (x, y) extruded from z = 0 to `height`, its
/// caps fans from the profile's first point (which must see the whole polygon).
inline std::string PrismObj(const std::vector<Eigen::Vector2d>& profile, double height) {
  std::ostringstream obj;
  obj.precision(17);
  const int n = static_cast<int>(profile.size());
  for (double z : {0.0, height})
    for (const Eigen::Vector2d& p : profile)
      obj << "v " << p.x() << " " << p.y() << " " << z << "\n";
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    obj << "f " << i + 1 << " " << j + 1 << " " << n + j + 1 << " " << n + i + 1 << "\n";
  }
  for (int k = 1; k + 1 < n; ++k) {
    obj << "f " << n + 1 << " " << n + k + 1 << " " << n + k + 2 << "\n";
    obj << "f 1 " << k + 2 << " " << k + 1 << "\n";
  }
  return obj.str();
}

/// A cylinder of `segments` sides: radius 1, height 2.
inline std::string CylinderObj(int segments) {
  std::vector<Eigen::Vector2d> circle;
  for (int i = 0; i < segments; ++i) {
    const double a = 2.0 * std::numbers::pi * i / segments;
    circle.emplace_back(std::cos(a), std::sin(a));
  }
  return PrismObj(circle, 2.0);
}

}  // namespace tubeplan::testing
