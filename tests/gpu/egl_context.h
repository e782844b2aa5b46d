// A headless desktop-OpenGL context through EGL on the first EGL device (NVIDIA's driver on a GPU
// machine), for the GPU tests and benchmarks of the CUDA-GL interop path. ok() is false, with why(),
// where there is no such device (CI, Mesa without a GPU): callers skip then.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <string>

namespace sylva::test {

class EglContext {
public:
    EglContext(int width, int height)
    {
        auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        auto platformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (!queryDevices || !platformDisplay) {
            fail("EGL has no device enumeration (EGL_EXT_device_enumeration)");
            return;
        }
        EGLDeviceEXT devices[8];
        EGLint n = 0;
        if (!queryDevices(8, devices, &n) || n == 0) {
            fail("no EGL device");
            return;
        }
        for (EGLint i = 0; i < n && m_display == EGL_NO_DISPLAY; ++i) {
            EGLDisplay d = platformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
            EGLint major = 0, minor = 0;
            if (d == EGL_NO_DISPLAY || !eglInitialize(d, &major, &minor)) continue;
            const char* vendor = eglQueryString(d, EGL_VENDOR);
            if (vendor && std::string(vendor).find("NVIDIA") != std::string::npos) m_display = d;
            else eglTerminate(d);
        }
        if (m_display == EGL_NO_DISPLAY) {
            fail("no NVIDIA EGL device");
            return;
        }
        const EGLint configAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                                        EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config;
        EGLint configs = 0;
        if (!eglChooseConfig(m_display, configAttribs, &config, 1, &configs) || configs < 1) {
            fail("no EGL config");
            return;
        }
        const EGLint surfaceAttribs[] = {EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE};
        m_surface = eglCreatePbufferSurface(m_display, config, surfaceAttribs);
        if (m_surface == EGL_NO_SURFACE || !eglBindAPI(EGL_OPENGL_API)) {
            fail("no EGL pbuffer surface");
            return;
        }
        m_context = eglCreateContext(m_display, config, EGL_NO_CONTEXT, nullptr);
        if (m_context == EGL_NO_CONTEXT || !eglMakeCurrent(m_display, m_surface, m_surface, m_context)) {
            fail("cannot make an OpenGL context current");
            return;
        }
        m_renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    }
    ~EglContext()
    {
        if (m_display == EGL_NO_DISPLAY) return;
        eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (m_context != EGL_NO_CONTEXT) eglDestroyContext(m_display, m_context);
        if (m_surface != EGL_NO_SURFACE) eglDestroySurface(m_display, m_surface);
        eglTerminate(m_display);
    }
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    bool ok() const { return m_why.empty() && m_context != EGL_NO_CONTEXT; }
    const std::string& why() const { return m_why; }
    const std::string& renderer() const { return m_renderer; }

private:
    void fail(const std::string& why) { m_why = why; }

    EGLDisplay m_display = EGL_NO_DISPLAY;
    EGLSurface m_surface = EGL_NO_SURFACE;
    EGLContext m_context = EGL_NO_CONTEXT;
    std::string m_why, m_renderer;
};

} // namespace sylva::test
