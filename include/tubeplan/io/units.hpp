#pragma once
// Quantities with units, as written in scene and plan files and on the command line: "5 mm",
// "3 MPa", "10 N/mm", "0.5", "90 deg". A plain number is taken as SI for the quantity it sets.
// Units are a small, tested table (see units.cpp for the list and README for why not udunits2).

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace tubeplan::io {

/// Exponents of the base dimensions; angle is kept as its own dimension so that "deg" cannot
/// set a pressure, while a plain number still sets an angle in radians.
struct Dimension {
  int length = 0;
  int mass = 0;
  int time = 0;
  int angle = 0;
  friend bool operator==(const Dimension&, const Dimension&) = default;
};

namespace dim {
inline constexpr Dimension kNone{};
inline constexpr Dimension kLength{1, 0, 0, 0};
inline constexpr Dimension kMass{0, 1, 0, 0};
inline constexpr Dimension kTime{0, 0, 1, 0};
inline constexpr Dimension kAngle{0, 0, 0, 1};
inline constexpr Dimension kForce{1, 1, -2, 0};
inline constexpr Dimension kPressure{-1, 1, -2, 0};
inline constexpr Dimension kStiffness{0, 1, -2, 0};  // N/m
inline constexpr Dimension kDamping{0, 1, -1, 0};    // N s/m
inline constexpr Dimension kTorque{2, 1, -2, 0};     // N m (also energy, J)
inline constexpr Dimension kFrequency{0, 0, -1, 0};
inline constexpr Dimension kVelocity{1, 0, -1, 0};
}  // namespace dim

/// A readable name for a dimension: "length", "force/length", "pressure", or "m^-1 kg s^-2".
std::string Describe(Dimension dimension);

struct Quantity {
  double value_si = 0.0;
  Dimension dimension;
  bool has_unit = false;  ///< false for a plain number
};

struct UnitError {
  std::size_t offset = 0;  ///< byte offset into the text where the problem starts
  std::string message;
};

struct QuantityResult {
  std::optional<Quantity> quantity;
  std::optional<UnitError> error;
};

/// Parses "<number> [unit expression]"; the unit expression is symbols with optional SI prefixes
/// joined by '*', '·', ' ' or '/', each with an optional integer exponent ("m^2", "s^-1").
/// Non-finite numbers ("nan", "inf") are errors.
QuantityResult ParseQuantity(std::string_view text);

/// ParseQuantity, then checks the dimension: a plain number is accepted as SI; a unit of another
/// dimension is an error naming both ("has a unit of length (mm), expected a force/length ...").
QuantityResult ParseQuantityAs(std::string_view text, Dimension expected);

}  // namespace tubeplan::io
