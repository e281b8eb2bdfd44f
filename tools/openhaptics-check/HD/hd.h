/* A minimal stand-in for OpenHaptics' HD/hd.h, for a compile check only: it declares just the
 * documented HD API types, constants and calls that src/device/openhaptics.cpp uses, with the
 * signatures of the OpenHaptics 3.4 reference. It is not the SDK (which Debian does not
 * package) and nothing links against it; its constants' values are not the SDK's. */
#ifndef TUBEPLAN_OPENHAPTICS_CHECK_HD_H
#define TUBEPLAN_OPENHAPTICS_CHECK_HD_H

#ifdef __cplusplus
extern "C" {
#endif

typedef unsigned int HHD;
typedef unsigned int HDenum;
typedef int HDint;
typedef double HDdouble;
typedef unsigned short HDushort;
typedef unsigned int HDErrorCode;
typedef const char* HDstring;
typedef unsigned int HDCallbackCode;
typedef unsigned long HDSchedulerHandle;
typedef HDCallbackCode (*HDSchedulerCallback)(void* pUserData);

typedef struct {
  HDErrorCode errorCode;
  int internalErrorCode;
  HHD hHD;
} HDErrorInfo;

#define HDCALLBACK
#define HD_DEFAULT_DEVICE ((const char*)0)
#define HD_INVALID_HANDLE 0xFFFFFFFFu
#define HD_SUCCESS 0x0000u
#define HD_DEVICE_ERROR(X) (((X).errorCode) != HD_SUCCESS)
#define HD_CALLBACK_DONE 0u
#define HD_MAX_SCHEDULER_PRIORITY 0xFFFFu
#define HD_FORCE_OUTPUT 0x4000u
#define HD_CURRENT_BUTTONS 0x2000u
#define HD_CURRENT_TRANSFORM 0x2052u
#define HD_CURRENT_VELOCITY 0x2051u
#define HD_CURRENT_ANGULAR_VELOCITY 0x2054u
#define HD_CURRENT_FORCE 0x2700u
#define HD_CURRENT_TORQUE 0x2701u
#define HD_NOMINAL_MAX_FORCE 0x2603u
#define HD_NOMINAL_MAX_TORQUE_FORCE 0x2609u
#define HD_NOMINAL_MAX_STIFFNESS 0x2601u
#define HD_NOMINAL_MAX_DAMPING 0x2602u
#define HD_USABLE_WORKSPACE_DIMENSIONS 0x2551u
#define HD_OUTPUT_DOF 0x2351u
#define HD_INPUT_DOF 0x2350u
#define HD_DEVICE_MODEL_TYPE 0x2501u
#define HD_CALIBRATION_OK 0x5000u
#define HD_CALIBRATION_ENCODER_RESET (1 << 0)

HHD hdInitDevice(HDstring pConfigName);
void hdDisableDevice(HHD hHD);
void hdMakeCurrentDevice(HHD hHD);
HDErrorInfo hdGetError(void);
void hdEnable(HDenum cap);
void hdDisable(HDenum cap);
void hdStartScheduler(void);
void hdStopScheduler(void);
void hdScheduleSynchronous(HDSchedulerCallback pCallback, void* pUserData, HDushort nPriority);
void hdBeginFrame(HHD hHD);
void hdEndFrame(HHD hHD);
void hdGetDoublev(HDenum pname, HDdouble* params);
void hdGetIntegerv(HDenum pname, HDint* params);
HDstring hdGetString(HDenum pname);
void hdSetDoublev(HDenum pname, const HDdouble* params);
HDenum hdCheckCalibration(void);
void hdUpdateCalibration(HDenum style);

#ifdef __cplusplus
}
#endif

#endif
