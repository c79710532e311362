// OpenGL ES 3 objects the passes use (internal to render/): a linked program with cached
// uniform locations, textures, render targets, interleaved vertex buffers. RAII: each
// deletes its GL object on the thread (and context) that made it.
#pragma once

#include <GLES3/gl3.h>

#include <map>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include "render/render.h"

namespace effects::render::detail {

struct Program {
  GLuint id = 0;
  std::map<std::string, GLint> locations;
  GLint at(const std::string& name) {
    auto it = locations.find(name);
    if (it == locations.end()) it = locations.emplace(name, glGetUniformLocation(id, name.c_str())).first;
    return it->second;
  }
  void set(const std::string& n, float v) { glUniform1f(at(n), v); }
  void set(const std::string& n, int v) { glUniform1i(at(n), v); }
  void set(const std::string& n, glm::vec2 v) { glUniform2f(at(n), v.x, v.y); }
  void set(const std::string& n, glm::vec3 v) { glUniform3f(at(n), v.x, v.y, v.z); }
  void set(const std::string& n, glm::vec4 v) { glUniform4f(at(n), v.x, v.y, v.z, v.w); }
  void set(const std::string& n, const glm::mat3& m) { glUniformMatrix3fv(at(n), 1, GL_FALSE, glm::value_ptr(m)); }
  void set(const std::string& n, const glm::mat4& m) { glUniformMatrix4fv(at(n), 1, GL_FALSE, glm::value_ptr(m)); }
};

inline Result<GLuint> compile(GLenum stage, const std::string& source) {
  GLuint s = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (ok) return s;
  char log[2048] = {};
  glGetShaderInfoLog(s, sizeof log, nullptr, log);
  glDeleteShader(s);
  return unsatisfiable("/renderer", std::string("shader does not compile: ") + log);
}

struct Texture {
  GLuint id = 0;
  GLenum target = GL_TEXTURE_2D;
  Texture() = default;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
  Texture(Texture&& o) noexcept : id(std::exchange(o.id, 0)), target(o.target) {}
  Texture& operator=(Texture&& o) noexcept {
    if (this != &o) {
      if (id) glDeleteTextures(1, &id);
      id = std::exchange(o.id, 0), target = o.target;
    }
    return *this;
  }
  ~Texture() {
    if (id) glDeleteTextures(1, &id);
  }
  void make(GLenum t) {
    target = t;
    glGenTextures(1, &id);
    glBindTexture(t, id);
    glTexParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    GLenum wrap = t == GL_TEXTURE_CUBE_MAP ? GL_CLAMP_TO_EDGE : GL_REPEAT;
    glTexParameteri(t, GL_TEXTURE_WRAP_S, wrap);
    glTexParameteri(t, GL_TEXTURE_WRAP_T, wrap);
  }
  void bind(int unit) const {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(target, id);
  }
};

inline Texture texture2D(int w, int h, GLenum internal, GLenum format, GLenum type, const void* data,
                         GLenum wrap = GL_REPEAT) {
  Texture t;
  t.make(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, format, type, data);
  return t;
}

// A colour texture (and optionally depth) to draw into.
struct Target {
  GLuint fbo = 0, depth = 0;
  Texture color;
  int width = 0, height = 0;
  GLenum format = 0;
  Target() = default;
  Target(const Target&) = delete;
  Target& operator=(const Target&) = delete;
  ~Target() { release(); }
  void release() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (depth) glDeleteRenderbuffers(1, &depth);
    fbo = depth = 0, color = Texture(), width = height = 0, format = 0;
  }
  // Made on first use and again only when the size, format or depth differ (a render thread
  // keeps its targets from frame to frame); bound for drawing either way.
  bool ensure(int w, int h, GLenum internal, bool withDepth) {
    if (fbo && width == w && height == h && format == internal && (depth != 0) == withDepth) {
      glBindFramebuffer(GL_FRAMEBUFFER, fbo);
      return true;
    }
    release();
    width = w, height = h, format = internal;
    const GLenum type = internal == GL_RGBA8 ? GL_UNSIGNED_BYTE : internal == GL_RGBA32F ? GL_FLOAT : GL_HALF_FLOAT;
    color = texture2D(w, h, internal, GL_RGBA, type, nullptr, GL_CLAMP_TO_EDGE);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color.id, 0);
    if (withDepth) {
      glGenRenderbuffers(1, &depth);
      glBindRenderbuffer(GL_RENDERBUFFER, depth);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    }
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE) return true;
    release();
    return false;
  }
  void use() const {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, width, height);
  }
};

// Interleaved float vertices with the given attribute sizes at locations 0, 1, ...; `usage`
// GL_STATIC_DRAW for vertices kept and drawn again (Gpu::spheres).
struct Vertices {
  GLuint vao = 0, vbo = 0, ibo = 0;
  Vertices(const Vertices&) = delete;
  Vertices& operator=(const Vertices&) = delete;
  Vertices(const std::vector<float>& data, std::vector<int> sizes, const std::vector<uint32_t>* indices = nullptr,
           GLenum usage = GL_STREAM_DRAW) {
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), usage);
    const int stride = std::accumulate(sizes.begin(), sizes.end(), 0);
    for (size_t i = 0, offset = 0; i < sizes.size(); offset += size_t(sizes[i]), ++i) {
      glEnableVertexAttribArray(GLuint(i));
      glVertexAttribPointer(GLuint(i), sizes[i], GL_FLOAT, GL_FALSE, stride * 4, reinterpret_cast<void*>(offset * 4));
    }
    if (indices) {
      glGenBuffers(1, &ibo);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices->size() * 4), indices->data(), usage);
    }
  }
  ~Vertices() {
    glBindVertexArray(0);
    glDeleteBuffers(1, &vbo);
    if (ibo) glDeleteBuffers(1, &ibo);
    glDeleteVertexArrays(1, &vao);
  }
};

}  // namespace effects::render::detail
