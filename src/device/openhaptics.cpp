#include <HD/hd.h>
#include <utility>

#include <tubeplan/device/openhaptics.hpp>

namespace tubeplan::device {

struct OpenHapticsDevice::State {
  HHD device = HD_INVALID_HANDLE;
  bool scheduler_running = false;
  bool six_dof_out = false;
  bool ok = true;
  std::uint64_t sequence = 0;
  // In: filled by the read callback, in the device's units (mm, mm/s, rad/s).
  HDdouble transform[16] = {};
  HDdouble velocity_mm_per_s[3] = {};
  HDdouble angular_velocity[3] = {};
  HDint buttons = 0;
  // Out: the limiter's wrench, in N and mN m.
  HDdouble force_N[3] = {};
  HDdouble torque_mNm[3] = {};
};

namespace {

std::string ErrorText(const char* what) {
  const HDErrorInfo error = hdGetError();
  if (!HD_DEVICE_ERROR(error)) return {};
  return std::string(what) + " failed (HD error " + std::to_string(error.errorCode) +
         ", internal " + std::to_string(error.internalErrorCode) + ")";
}

HDCallbackCode HDCALLBACK ReadCallback(void* user) {
  auto& s = *static_cast<OpenHapticsDevice::State*>(user);
  hdBeginFrame(s.device);
  hdGetDoublev(HD_CURRENT_TRANSFORM, s.transform);
  hdGetDoublev(HD_CURRENT_VELOCITY, s.velocity_mm_per_s);
  hdGetDoublev(HD_CURRENT_ANGULAR_VELOCITY, s.angular_velocity);
  hdGetIntegerv(HD_CURRENT_BUTTONS, &s.buttons);
  hdEndFrame(s.device);
  s.ok = !HD_DEVICE_ERROR(hdGetError());
  ++s.sequence;
  return HD_CALLBACK_DONE;
}

HDCallbackCode HDCALLBACK WriteCallback(void* user) {
  auto& s = *static_cast<OpenHapticsDevice::State*>(user);
  hdBeginFrame(s.device);
  hdSetDoublev(HD_CURRENT_FORCE, s.force_N);
  if (s.six_dof_out) hdSetDoublev(HD_CURRENT_TORQUE, s.torque_mNm);
  hdEndFrame(s.device);
  s.ok = !HD_DEVICE_ERROR(hdGetError());
  return HD_CALLBACK_DONE;
}

}  // namespace

OpenHapticsDevice::OpenHapticsDevice(std::string configuration)
    : configuration_(std::move(configuration)), state_(std::make_unique<State>()) {}
OpenHapticsDevice::~OpenHapticsDevice() { Close(); }

std::string OpenHapticsDevice::Open() {
  State& s = *state_;
  s.device = hdInitDevice(configuration_.empty() ? HD_DEFAULT_DEVICE : configuration_.c_str());
  if (std::string e = ErrorText("hdInitDevice"); !e.empty()) return e;
  hdMakeCurrentDevice(s.device);
  // The device's own nominal limits, not a table's (docs/live.md, "openhaptics (a real PHANToM)").
  HDdouble max_force_N = 0, max_torque_mNm = 0, stiffness_N_per_mm = 0, damping_Ns_per_mm = 0;
  HDdouble workspace_mm[6] = {};
  HDint output_dof = 3, input_dof = 3;
  hdGetDoublev(HD_NOMINAL_MAX_FORCE, &max_force_N);
  hdGetDoublev(HD_NOMINAL_MAX_STIFFNESS, &stiffness_N_per_mm);
  hdGetDoublev(HD_NOMINAL_MAX_DAMPING, &damping_Ns_per_mm);
  hdGetDoublev(HD_USABLE_WORKSPACE_DIMENSIONS, workspace_mm);
  hdGetIntegerv(HD_OUTPUT_DOF, &output_dof);
  hdGetIntegerv(HD_INPUT_DOF, &input_dof);
  s.six_dof_out = output_dof >= 6;
  if (s.six_dof_out) hdGetDoublev(HD_NOMINAL_MAX_TORQUE_FORCE, &max_torque_mNm);
  const HDstring model = hdGetString(HD_DEVICE_MODEL_TYPE);
  spec_.name = std::string("OpenHaptics ") + (model != nullptr ? model : "device");
  spec_.max_force_N = max_force_N;
  spec_.max_torque_Nm = max_torque_mNm * 1e-3;
  spec_.max_stiffness_N_per_m = stiffness_N_per_mm * 1e3;
  spec_.damping_Ns_per_m = damping_Ns_per_mm * 1e3;
  spec_.workspace_half_extents_m =
      0.5e-3 * Eigen::Vector3d(workspace_mm[3] - workspace_mm[0], workspace_mm[4] - workspace_mm[1],
                               workspace_mm[5] - workspace_mm[2]);
  spec_.button_count = 2;
  spec_.senses_rotation = input_dof >= 6;
  spec_.actuates_torque = s.six_dof_out;
  if (std::string e = ErrorText("reading the device's limits"); !e.empty()) return e;
  hdEnable(HD_FORCE_OUTPUT);
  hdStartScheduler();
  if (std::string e = ErrorText("hdStartScheduler"); !e.empty()) return e;
  s.scheduler_running = true;
  return {};
}

std::string OpenHapticsDevice::Calibrate() {
  if (hdCheckCalibration() != HD_CALIBRATION_OK) hdUpdateCalibration(HD_CALIBRATION_ENCODER_RESET);
  return ErrorText("calibration");
}

bool OpenHapticsDevice::Read(DeviceSample& sample) {
  State& s = *state_;
  if (!s.scheduler_running) return false;
  hdScheduleSynchronous(ReadCallback, &s, HD_MAX_SCHEDULER_PRIORITY);
  if (!s.ok) return false;
  // HD_CURRENT_TRANSFORM is column-major, translation in mm.
  const Eigen::Map<const Eigen::Matrix4d> T(s.transform);
  sample.sequence = s.sequence;
  sample.X_W_hand.linear() = T.topLeftCorner<3, 3>();
  sample.X_W_hand.translation() = 1e-3 * T.topRightCorner<3, 1>();
  sample.v_W_m_per_s = 1e-3 * Eigen::Vector3d(s.velocity_mm_per_s[0], s.velocity_mm_per_s[1],
                                              s.velocity_mm_per_s[2]);
  sample.w_W_rad_per_s =
      Eigen::Vector3d(s.angular_velocity[0], s.angular_velocity[1], s.angular_velocity[2]);
  sample.buttons = static_cast<std::uint32_t>(s.buttons);
  return true;
}

void OpenHapticsDevice::SendWrench(const Eigen::Vector3d& force_W_N,
                                   const Eigen::Vector3d& torque_W_Nm) {
  State& s = *state_;
  if (!s.scheduler_running) return;
  for (int i = 0; i < 3; ++i) {
    s.force_N[i] = force_W_N[i];
    s.torque_mNm[i] = torque_W_Nm[i] * 1e3;
  }
  hdScheduleSynchronous(WriteCallback, &s, HD_MAX_SCHEDULER_PRIORITY);
}

void OpenHapticsDevice::Close() {
  State& s = *state_;
  if (s.device == HD_INVALID_HANDLE) return;
  if (s.scheduler_running) {
    Disable();  // zero before the scheduler stops
    hdStopScheduler();
    s.scheduler_running = false;
  }
  hdDisable(HD_FORCE_OUTPUT);
  hdDisableDevice(s.device);
  s.device = HD_INVALID_HANDLE;
}

}  // namespace tubeplan::device
