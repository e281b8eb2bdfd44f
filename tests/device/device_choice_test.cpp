// `--device KIND[:ARGS]` parsed into a device choice: each kind, units converted to SI, and each
// mistake named with what was expected.
#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/device/device_choice.hpp>

using tubeplan::device::DeviceChoice;
using tubeplan::device::ParseDeviceChoice;

TEST_CASE("A device choice takes every kind with its arguments in SI", "[device]") {
  DeviceChoice c;
  std::string error;
  REQUIRE(ParseDeviceChoice("emulator:hand.csv,fast,mass=500g,stiffness=0.2N/mm", c, error));
  CHECK(c.kind == DeviceChoice::Kind::kEmulator);
  CHECK(c.emulator.trajectory == "hand.csv");
  CHECK(c.emulator.stepped);
  CHECK(c.emulator.hand.mass_kg == Approx(0.5));
  CHECK(c.emulator.hand.stiffness_N_per_m == Approx(200.0));

  DeviceChoice b;
  REQUIRE(ParseDeviceChoice("openigtlink://[::1]:18944,stale=200ms,max_force=3N", b, error));
  CHECK(b.kind == DeviceChoice::Kind::kOpenIGTLink);
  CHECK(b.igtl.host == "::1");
  CHECK(b.igtl.port == 18944);
  CHECK(b.igtl.stale_after_s == Approx(0.2));
  CHECK(b.igtl.spec.max_force_N == Approx(3.0));
  CHECK(b.igtl.spec.name == "haptic device (limits from --device)");

  DeviceChoice h;
  REQUIRE(ParseDeviceChoice("openhaptics:Right Arm", h, error));
  CHECK(h.kind == DeviceChoice::Kind::kOpenHaptics);
  CHECK(h.openhaptics_name == "Right Arm");
}

TEST_CASE("A bad device choice says which argument and what was expected", "[device]") {
  const auto error_of = [](const std::string& text) {
    DeviceChoice c;
    std::string error;
    CHECK_FALSE(ParseDeviceChoice(text, c, error));
    return error;
  };
  CHECK_THAT(error_of("robot"), Catch::Contains("unknown device kind \"robot\", expected "
                                                "emulator[:ARGS], openigtlink://HOST:PORT"));
  CHECK_THAT(error_of("emulator:mass=-1kg"), Catch::Contains("mass=\"-1kg\""));
  CHECK_THAT(error_of("emulator:speed=2"), Catch::Contains("unknown emulator argument \"speed\""));
  CHECK_THAT(error_of("openigtlink://host:0"), Catch::Contains("a port from 1 to 65535"));
  CHECK_THAT(error_of("openigtlink://host:18944,stale=2kg"), Catch::Contains("stale=\"2kg\""));
}
