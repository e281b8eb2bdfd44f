// The unit table, symbol by symbol, and the parser's errors.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/io/units.hpp>

namespace {

using tubeplan::io::Dimension;
using tubeplan::io::ParseQuantity;
using tubeplan::io::ParseQuantityAs;
namespace dim = tubeplan::io::dim;

// A conversion is one or two multiplications by a factor that is itself rounded: a few ulps.
constexpr double kRel = 4e-16;

double Si(const std::string& text) {
  const auto r = ParseQuantity(text);
  INFO(text << ": " << (r.error ? r.error->message : ""));
  REQUIRE(r.quantity);
  return r.quantity->value_si;
}

Dimension DimensionOf(const std::string& text) {
  const auto r = ParseQuantity(text);
  REQUIRE(r.quantity);
  return r.quantity->dimension;
}

}  // namespace

TEST_CASE("Quantities of the scene format convert to SI", "[units]") {
  CHECK(Si("5 mm") == Approx(0.005).epsilon(kRel));
  CHECK(DimensionOf("5 mm") == dim::kLength);
  CHECK(Si("3 MPa") == 3e6);
  CHECK(DimensionOf("3 MPa") == dim::kPressure);
  CHECK(Si("10 N/mm") == Approx(1e4).epsilon(kRel));
  CHECK(DimensionOf("10 N/mm") == dim::kStiffness);
  CHECK(Si("5 N s/m") == 5.0);
  CHECK(DimensionOf("5 N s/m") == dim::kDamping);
  CHECK(Si("90 deg") == Approx(std::numbers::pi / 2).epsilon(kRel));
  CHECK(Si("90 \u00B0") == Si("90 deg"));
  CHECK(DimensionOf("90 deg") == dim::kAngle);
  CHECK(Si("0.188 N m") == 0.188);
  CHECK(Si("0.188 N*m") == 0.188);
  CHECK(Si("0.188 N\u00B7m") == 0.188);
  CHECK(DimensionOf("0.188 N m") == dim::kTorque);
  CHECK(Si("1 kHz") == 1000.0);
  CHECK(DimensionOf("1 s^-1") == dim::kFrequency);
  CHECK(Si("2 m^2") == 2.0);
  CHECK(DimensionOf("2 m^2") == Dimension{2, 0, 0, 0});
  CHECK(Si("3 mm^2") == Approx(3e-6).epsilon(kRel));
  // '/' divides only the next factor: kg/m/s = kg m^-1 s^-1 (the dimension of viscosity).
  CHECK(DimensionOf("1 kg/m/s") == Dimension{-1, 1, -1, 0});
  CHECK(Si("1 g") == 1e-3);
  CHECK(Si("1 min") == 60.0);
  CHECK(Si("1 ms") == 1e-3);  // exact symbol first: "ms" is not a metre-second
  CHECK(Si("5mm") == Si("5 mm"));
  CHECK(Si("  .5 mm  ") == Approx(5e-4).epsilon(kRel));
  CHECK(Si("+2 N") == 2.0);
  CHECK(Si("-3.2e-3 m") == -3.2e-3);
  CHECK(Si("1e-400") == 0.0);  // underflow is zero, not an error
}

TEST_CASE("Both micro signs mean micro", "[units]") {
  CHECK(Si("7 \u00B5m") == Approx(7e-6).epsilon(kRel));  // U+00B5 MICRO SIGN
  CHECK(Si("7 \u03BCm") == Approx(7e-6).epsilon(kRel));  // U+03BC GREEK SMALL LETTER MU
  CHECK(Si("7 um") == Approx(7e-6).epsilon(kRel));
}

TEST_CASE("Every prefix with every prefixable symbol", "[units]") {
  // An independent table: the SI values of the prefixes and symbols, typed from the SI brochure.
  const std::vector<std::pair<std::string, double>> prefixes = {
      {"", 1.0},   {"G", 1e9},  {"M", 1e6},  {"k", 1e3},       {"d", 1e-1},
      {"c", 1e-2}, {"m", 1e-3}, {"u", 1e-6}, {"\u00B5", 1e-6}, {"n", 1e-9}};
  const std::vector<std::pair<std::string, double>> symbols = {
      {"m", 1.0}, {"g", 1e-3}, {"s", 1.0},  {"N", 1.0},  {"Pa", 1.0},
      {"J", 1.0}, {"W", 1.0},  {"Hz", 1.0}, {"rad", 1.0}};
  for (const auto& [prefix, p] : prefixes) {
    for (const auto& [symbol, f] : symbols) {
      const std::string text = "1 " + prefix + symbol;
      CAPTURE(text);
      const auto r = ParseQuantity(text);
      REQUIRE(r.quantity);
      CHECK(r.quantity->value_si == Approx(p * f).epsilon(kRel));
      CHECK(r.quantity->has_unit);
    }
  }
}

TEST_CASE("A plain number has no unit and is SI for whatever it sets", "[units]") {
  const auto r = ParseQuantity("0.5");
  REQUIRE(r.quantity);
  CHECK_FALSE(r.quantity->has_unit);
  CHECK(r.quantity->value_si == 0.5);
  const auto as_pressure = ParseQuantityAs("3", dim::kPressure);
  REQUIRE(as_pressure.quantity);
  CHECK(as_pressure.quantity->value_si == 3.0);
  CHECK(as_pressure.quantity->dimension == dim::kPressure);
}

TEST_CASE("Malformed quantities are errors at the right offset", "[units]") {
  struct Case {
    std::string text;
    std::size_t offset;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"nan", 0, "the number is not finite, expected a finite number"},
      {"inf", 0, "the number is not finite, expected a finite number"},
      {"-inf mm", 0, "the number is not finite, expected a finite number"},
      {"1e999", 0, "the number is too large, expected a finite number"},
      {"", 0, "expected a number, found nothing"},
      {"mm", 0, "expected a number, found 'mm'"},
      {"5 furlong", 2,
       "unknown unit 'furlong', expected one of m, g, s, min, N, Pa, J, W, Hz, rad, deg with an "
       "optional prefix G M k c d m u \u00B5 n"},
      {"5 mdeg", 2,
       "unknown unit 'mdeg', expected one of m, g, s, min, N, Pa, J, W, Hz, rad, deg with an "
       "optional prefix G M k c d m u \u00B5 n"},
      {"5 mm^", 5, "expected an integer power after '^', such as m^2 or s^-1"},
      {"5 mm^x", 5, "expected an integer power after '^', such as m^2 or s^-1"},
      {"5 mm^0", 5, "power 0 out of range, expected a non-zero integer from -9 to 9"},
      {"5 N//m", 4, "unexpected '/', expected a unit such as mm or N"},
      {"5 N*", 4, "expected a unit after the operator"},
      {"5 mm,", 4, "unexpected ',' in the unit, expected '*', '/', '^' or a space"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.text);
    const auto r = ParseQuantity(c.text);
    REQUIRE_FALSE(r.quantity);
    REQUIRE(r.error);
    CHECK(r.error->offset == c.offset);
    CHECK(r.error->message == c.message);
  }
}

TEST_CASE("A unit of the wrong dimension names both dimensions", "[units]") {
  const auto r = ParseQuantityAs("5 mm", dim::kForce);
  REQUIRE(r.error);
  CHECK(r.error->offset == 2);
  CHECK(r.error->message == "has a unit of length (mm), expected a force such as \"2 N\"");
  const auto damping = ParseQuantityAs("1e-3 N s/m", dim::kStiffness);
  REQUIRE(damping.error);
  CHECK(damping.error->offset == 5);
  CHECK(damping.error->message ==
        "has a unit of force*time/length (N s/m), expected a force/length such as \"10 N/mm\"");
  // Angles are a dimension of their own: degrees cannot set a length.
  CHECK(ParseQuantityAs("90 deg", dim::kLength).error);
  // "an angle", not "a angle".
  CHECK(ParseQuantityAs("5 mm", dim::kAngle).error->message ==
        "has a unit of length (mm), expected an angle such as \"90 deg\"");
}

TEST_CASE("Numbers round-trip through their shortest decimal form", "[units]") {
  // from_chars is correctly rounded: any double printed with 17 digits parses back to itself.
  std::mt19937_64 rng(12345u);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  for (int i = 0; i < 2000; ++i) {
    const double x = std::ldexp(mantissa(rng), exponent(rng));
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", x);
    CAPTURE(text);
    CHECK(Si(text) == x);
  }
}

TEST_CASE("Describe names common dimensions and spells out the rest", "[units]") {
  CHECK(tubeplan::io::Describe(dim::kStiffness) == "force/length");
  CHECK(tubeplan::io::Describe(Dimension{-1, 1, -1, 0}) == "m^-1 kg s^-1");
  CHECK(tubeplan::io::Describe(Dimension{2, 0, 0, 0}) == "m^2");
}
