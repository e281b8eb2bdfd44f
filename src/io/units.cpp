// The unit table and the quantity parser. Kept small on purpose: the symbols a scene, plan or
// command line needs, every one tested (tests/io/units_test.cpp). README says why not udunits2.
//
// Grammar:  quantity := ws number [ws unit-expression] ws
//           unit-expression := factor { ('*' | '·' | ' '+ | '/') factor }
//           factor := [prefix] symbol ['^' integer]
// A '/' divides only the factor right after it: "N/mm" = N mm^-1, "N s/m" = N s m^-1,
// "kg/m/s" = kg m^-1 s^-1.
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>

#include <tubeplan/io/units.hpp>

#include "text_file.hpp"

namespace tubeplan::io {
namespace {

struct Symbol {
  std::string_view text;
  double factor;  // to SI
  Dimension dimension;
  bool prefixable;
};

// Exact symbols are matched before prefix + symbol, so "m" is the metre, "min" the minute and
// "mm" the millimetre.
constexpr std::array<Symbol, 12> kSymbols = {{
    {"m", 1.0, dim::kLength, true},
    {"g", 1e-3, dim::kMass, true},
    {"s", 1.0, dim::kTime, true},
    {"min", 60.0, dim::kTime, false},
    {"N", 1.0, dim::kForce, true},
    {"Pa", 1.0, dim::kPressure, true},
    {"J", 1.0, dim::kTorque, true},
    {"W", 1.0, Dimension{2, 1, -3, 0}, true},
    {"Hz", 1.0, dim::kFrequency, true},
    {"rad", 1.0, dim::kAngle, true},
    {"deg", std::numbers::pi / 180.0, dim::kAngle, false},
    {"\u00B0", std::numbers::pi / 180.0, dim::kAngle, false},
}};

struct Prefix {
  std::string_view text;
  double factor;
};

constexpr std::array<Prefix, 10> kPrefixes = {{
    {"G", 1e9},
    {"M", 1e6},
    {"k", 1e3},
    {"c", 1e-2},
    {"m", 1e-3},
    {"u", 1e-6},
    {"\u00B5", 1e-6},  // micro sign
    {"\u03BC", 1e-6},  // Greek mu
    {"n", 1e-9},
    {"d", 1e-1},
}};

constexpr std::string_view kKnownUnits =
    "m, g, s, min, N, Pa, J, W, Hz, rad, deg with an optional prefix G M k c d m u \u00B5 n";

Dimension Add(Dimension a, Dimension b, int power) {
  return {a.length + power * b.length, a.mass + power * b.mass, a.time + power * b.time,
          a.angle + power * b.angle};
}

bool IsSpace(char c) { return c == ' ' || c == '\t'; }

// A symbol is a run of letters (ASCII or the multi-byte µ, μ, °) not containing an operator.
bool IsSymbolByte(unsigned char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c >= 0x80;
}

bool StartsWith(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

// "·" is two bytes in UTF-8; it is an operator, not part of a symbol.
constexpr std::string_view kMiddleDot = "\u00B7";

const Symbol* FindSymbol(std::string_view word, double& factor) {
  for (const Symbol& s : kSymbols) {
    if (word == s.text) {
      factor = s.factor;
      return &s;
    }
  }
  for (const Prefix& p : kPrefixes) {
    if (!StartsWith(word, p.text)) continue;
    const std::string_view rest = word.substr(p.text.size());
    for (const Symbol& s : kSymbols) {
      if (rest == s.text && s.prefixable) {
        factor = p.factor * s.factor;
        return &s;
      }
    }
  }
  return nullptr;
}

// The dimensions with a name of their own, and a unit to suggest when one is expected.
struct NamedDimension {
  Dimension dimension;
  const char* name;
  const char* example;
};
constexpr std::array<NamedDimension, 12> kNamedDimensions = {{
    {dim::kNone, "dimensionless number", "0.5 (no unit)"},
    {dim::kLength, "length", "\"5 mm\""},
    {dim::kMass, "mass", "\"1 kg\""},
    {dim::kTime, "time", "\"1 ms\""},
    {dim::kAngle, "angle", "\"90 deg\""},
    {dim::kForce, "force", "\"2 N\""},
    {dim::kPressure, "pressure", "\"3 MPa\""},
    {dim::kStiffness, "force/length", "\"10 N/mm\""},
    {dim::kDamping, "force*time/length", "\"5 N s/m\""},
    {dim::kTorque, "torque or energy", "\"0.188 N m\""},
    {dim::kFrequency, "frequency", "\"1 kHz\""},
    {dim::kVelocity, "velocity", "\"10 mm/s\""},
}};

const NamedDimension* FindNamed(Dimension d) {
  for (const NamedDimension& n : kNamedDimensions)
    if (n.dimension == d) return &n;
  return nullptr;
}

std::string ExampleUnit(Dimension d) {
  const NamedDimension* named = FindNamed(d);
  return named != nullptr ? named->example : "a plain SI number";
}

QuantityResult Fail(std::size_t offset, std::string message) {
  return {std::nullopt, UnitError{offset, std::move(message)}};
}

}  // namespace

std::string Describe(Dimension d) {
  if (const NamedDimension* named = FindNamed(d)) return named->name;
  std::string text;
  auto term = [&text](const char* symbol, int power) {
    if (power == 0) return;
    if (!text.empty()) text += ' ';
    text += symbol;
    if (power != 1) text += '^' + std::to_string(power);
  };
  term("m", d.length);
  term("kg", d.mass);
  term("s", d.time);
  term("rad", d.angle);
  return text;
}

namespace {

// ParseQuantity, also telling where the unit expression starts (text.size() when there is none).
QuantityResult Parse(std::string_view text, std::size_t& unit_offset) {
  unit_offset = text.size();
  std::size_t i = 0;
  const std::size_t n = text.size();
  while (i < n && IsSpace(text[i])) ++i;
  std::size_t end = n;
  while (end > i && IsSpace(text[end - 1])) --end;
  if (i == end) return Fail(i, "expected a number, found nothing");

  // from_chars does not take a leading '+' (it does take ".5"): the '+' is skipped here.
  std::size_t number_start = i;
  if (text[i] == '+') {
    ++i;
    if (i < end && text[i] == '-') return Fail(i, "expected a number, found '+-'");
  }
  double value = 0.0;
  const char* first = text.data() + i;
  const char* last = text.data() + end;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec == std::errc::invalid_argument || ptr == first) {
    std::size_t word_end = i;
    while (word_end < end && !IsSpace(text[word_end])) ++word_end;
    const std::string_view word = text.substr(number_start, word_end - number_start);
    // YAML's own spellings of NaN and infinity (.nan, .NaN, .inf, -.Inf) are not numbers to
    // from_chars; they deserve the same message as nan and inf.
    std::string_view bare = word;
    if (!bare.empty() && (bare.front() == '-' || bare.front() == '+')) bare.remove_prefix(1);
    if (bare.size() == 4 && bare.front() == '.') {
      std::string lower;
      for (const char c : bare.substr(1))
        lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (lower == "nan" || lower == "inf")
        return Fail(number_start, "the number is not finite, expected a finite number");
    }
    return Fail(number_start, "expected a number, found '" + Abbreviate(word) + "'");
  }
  if (ec == std::errc::result_out_of_range) {
    // from_chars says out of range for both overflow and underflow and leaves value unset. A
    // number that underflows (its exponent is negative) is zero for every purpose here; one that
    // overflows is an error.
    const std::string_view digits(first, static_cast<std::size_t>(ptr - first));
    const std::size_t e = digits.find_first_of("eE");
    const bool underflow =
        e != std::string_view::npos && e + 1 < digits.size() && digits[e + 1] == '-';
    if (!underflow) return Fail(number_start, "the number is too large, expected a finite number");
    value = digits.front() == '-' ? -0.0 : 0.0;
  } else if (!std::isfinite(value)) {
    return Fail(number_start, "the number is not finite, expected a finite number");
  }
  i = static_cast<std::size_t>(ptr - text.data());

  Quantity q;
  q.value_si = value;
  if (i == end) return {q, std::nullopt};

  // A unit expression follows, after optional spaces.
  while (i < end && IsSpace(text[i])) ++i;
  unit_offset = i;
  bool expect_factor = true;
  int power_sign = 1;
  while (i < end) {
    if (!expect_factor) {
      // Between factors: '*', '·', '/', or spaces (a space alone multiplies).
      std::size_t j = i;
      while (j < end && IsSpace(text[j])) ++j;
      if (j < end && (text[j] == '*' || text[j] == '/' || StartsWith(text.substr(j), kMiddleDot))) {
        power_sign = text[j] == '/' ? -1 : 1;
        j += text[j] == '*' || text[j] == '/' ? 1 : kMiddleDot.size();
        while (j < end && IsSpace(text[j])) ++j;
      } else if (j == i) {
        return Fail(i, "unexpected '" + std::string(1, text[i]) +
                           "' in the unit, expected '*', '/', '^' or a space");
      } else {
        power_sign = 1;
      }
      i = j;
      expect_factor = true;
      continue;
    }
    const std::size_t word_start = i;
    while (i < end && IsSymbolByte(static_cast<unsigned char>(text[i])) &&
           !StartsWith(text.substr(i), kMiddleDot))
      ++i;
    const std::string_view word = text.substr(word_start, i - word_start);
    if (word.empty()) {
      return Fail(word_start, i < end ? "unexpected '" + std::string(1, text[i]) +
                                            "', expected a unit such as mm or N"
                                      : std::string("expected a unit after the operator"));
    }
    double factor = 1.0;
    const Symbol* symbol = FindSymbol(word, factor);
    if (symbol == nullptr) {
      return Fail(word_start, "unknown unit '" + Abbreviate(word) + "', expected one of " +
                                  std::string(kKnownUnits));
    }
    int power = 1;
    if (i < end && text[i] == '^') {
      const std::size_t power_start = ++i;
      const auto [p_end, p_ec] = std::from_chars(text.data() + i, text.data() + end, power);
      if (p_ec != std::errc() || p_end == text.data() + i) {
        return Fail(power_start, "expected an integer power after '^', such as m^2 or s^-1");
      }
      if (power < -9 || power > 9 || power == 0) {
        return Fail(power_start, "power " + std::to_string(power) +
                                     " out of range, expected a non-zero integer from -9 to 9");
      }
      i = static_cast<std::size_t>(p_end - text.data());
    }
    const int signed_power = power_sign * power;
    q.value_si *= std::pow(factor, signed_power);
    q.dimension = Add(q.dimension, symbol->dimension, signed_power);
    q.has_unit = true;
    expect_factor = false;
  }
  if (expect_factor) return Fail(end, "expected a unit after the operator");
  if (!std::isfinite(q.value_si)) {
    return Fail(number_start, "the quantity overflows in SI units, expected a finite number");
  }
  return {q, std::nullopt};
}

}  // namespace

QuantityResult ParseQuantity(std::string_view text) {
  std::size_t unit_offset = 0;
  return Parse(text, unit_offset);
}

QuantityResult ParseQuantityAs(std::string_view text, Dimension expected) {
  std::size_t unit_offset = 0;
  QuantityResult result = Parse(text, unit_offset);
  if (!result.quantity) return result;
  Quantity& q = *result.quantity;
  if (!q.has_unit) {
    q.dimension = expected;  // a plain number is SI for whatever it sets
    return result;
  }
  if (q.dimension == expected) return result;
  std::string_view unit = text.substr(unit_offset);
  while (!unit.empty() && IsSpace(unit.back())) unit.remove_suffix(1);
  const std::string wanted = Describe(expected);
  const bool vowel = std::string_view("aeiou").find(wanted.front()) != std::string_view::npos;
  return Fail(unit_offset, "has a unit of " + Describe(q.dimension) + " (" + Abbreviate(unit) +
                               "), expected " + (vowel ? "an " : "a ") + wanted + " such as " +
                               ExampleUnit(expected));
}

}  // namespace tubeplan::io
