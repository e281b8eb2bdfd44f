#include <cstdlib>

#include <tubeplan/device/device_choice.hpp>
#include <tubeplan/device/openhaptics.hpp>
#include <tubeplan/io/units.hpp>

namespace tubeplan::device {
namespace {

// A `key=value` argument with a unit, into `target` (SI); false and `error` when bad.
bool ParseQuantityArg(const std::string& key, const std::string& value, io::Dimension dimension,
                      double& target, std::string& error) {
  const io::QuantityResult q = io::ParseQuantityAs(value, dimension);
  if (!q.quantity || !(q.quantity->value_si > 0.0)) {
    error = "--device: " + key + "=\"" + value +
            "\": " + (q.quantity ? "must be greater than zero" : q.error->message);
    return false;
  }
  target = q.quantity->value_si;
  return true;
}

// Calls `each` on every comma-separated item of `list`; stops at the first false.
template <class F>
bool ForEachItem(const std::string& list, F each) {
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = list.find(',', start);
    const std::string item =
        list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? list.size() + 1 : comma + 1;
    if (!item.empty() && !each(item)) return false;
  }
  return true;
}

bool ParseEmulator(const std::string& rest, EmulatorArgs& args, std::string& error) {
  return ForEachItem(rest, [&](const std::string& item) {
    const std::size_t eq = item.find('=');
    if (item == "fast") {
      args.stepped = true;
      return true;
    }
    if (eq == std::string::npos) {
      args.trajectory = item;
      return true;
    }
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "trajectory") {
      args.trajectory = value;
      return true;
    }
    if (key == "mass")
      return ParseQuantityArg(key, value, io::dim::kMass, args.hand.mass_kg, error);
    if (key == "stiffness")
      return ParseQuantityArg(key, value, io::dim::kStiffness, args.hand.stiffness_N_per_m, error);
    if (key == "damping")
      return ParseQuantityArg(key, value, io::dim::kDamping, args.hand.damping_Ns_per_m, error);
    error = "--device: unknown emulator argument \"" + key +
            "\", expected FILE.csv, trajectory=FILE, fast, mass=, stiffness= or damping=";
    return false;
  });
}

// `HOST:PORT[,key=value...]`; HOST may be an IPv6 address in brackets.
bool ParseOpenIGTLink(const std::string& text, const std::string& rest, OpenIGTLinkOptions& o,
                      std::string& error) {
  const std::string address = rest.substr(0, rest.find(','));
  std::size_t colon = address.rfind(':');
  if (!address.empty() && address.front() == '[') {
    const std::size_t close = address.find(']');
    colon = close == std::string::npos ? std::string::npos : address.find(':', close);
    o.host = address.substr(1, close == std::string::npos ? std::string::npos : close - 1);
  } else {
    o.host = address.substr(0, colon);
  }
  const std::string port = colon == std::string::npos ? "" : address.substr(colon + 1);
  char* end = nullptr;
  const long number = std::strtol(port.c_str(), &end, 10);
  if (o.host.empty() || port.empty() || *end != '\0' || number < 1 || number > 65535) {
    error = "--device \"" + text +
            "\": expected openigtlink://HOST:PORT with a port from 1 to 65535 (OpenIGTLink's is "
            "18944)";
    return false;
  }
  o.port = int(number);
  bool limits_given = false;
  const bool ok = ForEachItem(rest.substr(address.size()), [&](const std::string& item) {
    const std::size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    struct Param {
      const char* name;
      io::Dimension dimension;
      double* target;
      bool limit;
    };
    const Param params[] = {
        {"timeout", io::dim::kTime, &o.connect_timeout_s, false},
        {"stale", io::dim::kTime, &o.stale_after_s, false},
        {"max_force", io::dim::kForce, &o.spec.max_force_N, true},
        {"max_torque", io::dim::kTorque, &o.spec.max_torque_Nm, true},
        {"max_stiffness", io::dim::kStiffness, &o.spec.max_stiffness_N_per_m, true},
        {"damping", io::dim::kDamping, &o.spec.damping_Ns_per_m, true}};
    for (const Param& p : params) {
      if (key != p.name) continue;
      limits_given = limits_given || p.limit;
      return ParseQuantityArg(key, value, p.dimension, *p.target, error);
    }
    error = "--device: unknown openigtlink argument \"" + key +
            "\", expected timeout=, stale=, max_force=, max_torque=, max_stiffness= or damping=";
    return false;
  });
  // The bridge reports no limits: name whose they are.
  if (limits_given) o.spec.name = "haptic device (limits from --device)";
  return ok;
}

}  // namespace

bool ParseDeviceChoice(const std::string& text, DeviceChoice& choice, std::string& error) {
  static const std::string kIgtl = "openigtlink://";
  if (text.compare(0, kIgtl.size(), kIgtl) == 0) {
    choice.kind = DeviceChoice::Kind::kOpenIGTLink;
    return ParseOpenIGTLink(text, text.substr(kIgtl.size()), choice.igtl, error);
  }
  const std::string kind = text.substr(0, text.find(':'));
  const std::string rest = text.size() == kind.size() ? "" : text.substr(kind.size() + 1);
  if (kind == "emulator") {
    choice.kind = DeviceChoice::Kind::kEmulator;
    return ParseEmulator(rest, choice.emulator, error);
  }
  if (kind == "openhaptics") {
    choice.kind = DeviceChoice::Kind::kOpenHaptics;
    choice.openhaptics_name = rest;
    return true;
  }
  error = "--device \"" + text + "\": unknown device kind \"" + kind +
          "\", expected emulator[:ARGS], openigtlink://HOST:PORT[,ARGS] or openhaptics[:NAME]";
  return false;
}

std::unique_ptr<HapticDevice> MakeDevice(const DeviceChoice& choice, Clock& clock,
                                         const trajectories::Trajectory& target,
                                         std::string& error) {
  switch (choice.kind) {
    case DeviceChoice::Kind::kEmulator:
      return std::make_unique<EmulatorDevice>(clock, target, choice.emulator.hand);
    case DeviceChoice::Kind::kOpenIGTLink:
      return std::make_unique<OpenIGTLinkDevice>(choice.igtl);
    case DeviceChoice::Kind::kOpenHaptics:
      break;
  }
  return MakeOpenHapticsDevice(choice.openhaptics_name, error);
}

}  // namespace tubeplan::device
