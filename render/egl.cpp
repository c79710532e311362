// EGL without a window: a device display (GPUs, or Mesa's software device) or Mesa's
// surfaceless platform; an OpenGL ES 3 context made current with no surface at all.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <cstring>
#include <mutex>

#include "internal.h"

namespace effects::render::detail {
namespace {

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

// One display per platform for the process: eglInitialize is not reference counted, so a
// display is initialised once and never terminated while contexts may live on it.
struct Display {
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string error;
};

Display openDevice() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client, "EGL_EXT_platform_device")) return {EGL_NO_DISPLAY, "EGL_EXT_platform_device is missing"};
  auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto queryString = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  auto platformDisplay =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!queryDevices || !queryString || !platformDisplay) return {EGL_NO_DISPLAY, "EGL device functions are missing"};
  EGLDeviceEXT devices[16];
  EGLint count = 0;
  if (!queryDevices(16, devices, &count) || count == 0) return {EGL_NO_DISPLAY, "no EGL device"};
  // A hardware device first; Mesa's software device (llvmpipe) last.
  int pick = 0;
  for (int i = count - 1; i >= 0; --i)
    if (!hasExtension(queryString(devices[i], EGL_EXTENSIONS), "EGL_MESA_device_software")) pick = i;
  for (int attempt = 0; attempt < count; ++attempt) {
    int i = (pick + attempt) % count;
    EGLDisplay d = platformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr)) return {d, ""};
  }
  return {EGL_NO_DISPLAY, "no EGL device could be initialised"};
}

Display openSurfaceless() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client, "EGL_MESA_platform_surfaceless"))
    return {EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless is missing"};
  auto platformDisplay =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  EGLDisplay d =
      platformDisplay ? platformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr) : EGL_NO_DISPLAY;
  if (d == EGL_NO_DISPLAY || !eglInitialize(d, nullptr, nullptr))
    return {EGL_NO_DISPLAY, "the surfaceless EGL display could not be initialised"};
  return {d, ""};
}

const Display& display(const std::string& platform) {
  static std::once_flag deviceOnce, surfacelessOnce;
  static Display device, surfaceless;
  if (platform == "device") {
    std::call_once(deviceOnce, [] { device = openDevice(); });
    return device;
  }
  std::call_once(surfacelessOnce, [] { surfaceless = openSurfaceless(); });
  return surfaceless;
}

Result<EglContext> contextOn(const std::string& platform) {
  const Display& d = display(platform);
  if (d.display == EGL_NO_DISPLAY) return Error{ErrorKind::kUnsatisfiable, "/renderer", platform + ": " + d.error};
  if (!hasExtension(eglQueryString(d.display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
    return Error{ErrorKind::kUnsatisfiable, "/renderer", platform + ": EGL_KHR_surfaceless_context is missing"};
  if (!eglBindAPI(EGL_OPENGL_ES_API)) return Error{ErrorKind::kUnsatisfiable, "/renderer", platform + ": no OpenGL ES"};
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  // No config: the context only ever draws into framebuffer objects.
  EGLContext c = eglCreateContext(d.display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (c == EGL_NO_CONTEXT) {
    EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
    EGLConfig config;
    EGLint n = 0;
    if (eglChooseConfig(d.display, configAttributes, &config, 1, &n) && n > 0)
      c = eglCreateContext(d.display, config, EGL_NO_CONTEXT, attributes);
  }
  if (c == EGL_NO_CONTEXT)
    return Error{ErrorKind::kUnsatisfiable, "/renderer",
                 platform + ": no OpenGL ES 3 context (EGL error " + std::to_string(eglGetError()) + ")"};
  if (!eglMakeCurrent(d.display, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) {
    eglDestroyContext(d.display, c);
    return Error{ErrorKind::kUnsatisfiable, "/renderer", platform + ": the context cannot be made current"};
  }
  return EglContext{d.display, c, platform};
}

}  // namespace

Result<EglContext> createContext(const std::string& requested) {
  std::string platform = requested;
  if (platform.empty()) {
    const char* env = std::getenv("EFFECTD_EGL_PLATFORM");
    platform = env && *env ? env : "auto";
  }
  if (platform == "device" || platform == "surfaceless") return contextOn(platform);
  if (platform != "auto")
    return Error{ErrorKind::kInvalidArgument, "/renderer",
                 "EGL platform \"" + platform + "\" is not one of auto, device, surfaceless"};
  auto device = contextOn("device");
  if (device.ok()) return device;
  auto surfaceless = contextOn("surfaceless");
  if (surfaceless.ok()) return surfaceless;
  return Error{ErrorKind::kUnsatisfiable, "/renderer", device.error().message + "; " + surfaceless.error().message};
}

void destroyContext(EglContext& c) {
  if (!c.context) return;
  eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(c.display, c.context);
  eglReleaseThread();
  c.context = nullptr;
}

}  // namespace effects::render::detail
