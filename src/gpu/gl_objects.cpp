#include "gpu/gl_objects.h"

#include "core/error.h"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace ff::gpu {

namespace {
thread_local std::string debugMessages; // the context is current on one thread only
}

void recordDebugMessage(std::string message) {
    if (!debugMessages.empty()) debugMessages += "; ";
    debugMessages += message;
}

void checkGl(const char* what) {
    const GLenum e = glGetError();
    std::string messages;
    messages.swap(debugMessages);
    if (e == GL_NO_ERROR && messages.empty()) return;
    char code[16];
    std::snprintf(code, sizeof code, "%04x", e);
    throwRuntimeError((e != GL_NO_ERROR ? std::string("OpenGL error 0x") + code : std::string("OpenGL debug message")) +
                      " in " + what + (messages.empty() ? "" : ": " + messages));
}

Buffer::Buffer() {
    glCreateBuffers(1, &id_);
}
Buffer::~Buffer() {
    glDeleteBuffers(1, &id_);
}

void Buffer::upload(const void* data, std::size_t bytes) {
    // The same size keeps the storage (a reallocation costs more than the copy on some drivers).
    if (bytes == bytes_ && bytes > 0) {
        if (data) glNamedBufferSubData(id_, 0, static_cast<GLsizeiptr>(bytes), data);
    } else {
        glNamedBufferData(id_, static_cast<GLsizeiptr>(bytes), data, GL_DYNAMIC_DRAW);
        bytes_ = bytes;
    }
    checkGl("a buffer upload");
}

void Buffer::zeros(std::size_t bytes) {
    if (bytes != bytes_) upload(nullptr, bytes);
    // A null pattern fills with zeros.
    glClearNamedBufferData(id_, GL_R32F, GL_RED, GL_FLOAT, nullptr);
    checkGl("a buffer clear");
}

void Buffer::zeros(std::size_t offset, std::size_t bytes) {
    glClearNamedBufferSubData(id_, GL_R32F, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), GL_RED,
                              GL_FLOAT, nullptr);
    checkGl("a buffer clear");
}

Texture::Texture() = default;
Texture::~Texture() {
    if (id_) glDeleteTextures(1, &id_);
}

void Texture::upload(const float* rgb, int width, int height) {
    if (!id_ || width != width_ || height != height_) {
        if (id_) glDeleteTextures(1, &id_);
        glCreateTextures(GL_TEXTURE_2D, 1, &id_);
        glTextureStorage2D(id_, 1, GL_RGB32F, width, height);
        width_ = width;
        height_ = height;
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(id_, 0, 0, 0, width, height, GL_RGB, GL_FLOAT, rgb);
    checkGl("a texture upload");
}

void dispatchGroups(GLuint n) {
    glDispatchCompute(std::min(n, kMaxWorkGroups), (n + kMaxWorkGroups - 1) / kMaxWorkGroups, 1);
}

void Buffer::download(void* data, std::size_t bytes) const {
    glGetNamedBufferSubData(id_, 0, static_cast<GLsizeiptr>(bytes), data);
    checkGl("a buffer download");
}

ComputeProgram::ComputeProgram(std::string_view name, std::string_view source, int localSize) : localSize_(localSize) {
    // The #version line stays first; LOCAL_SIZE goes right after it.
    std::string text(source);
    const std::size_t eol = text.find('\n');
    text.insert(eol == std::string::npos ? text.size() : eol + 1,
                "#define LOCAL_SIZE " + std::to_string(localSize) + "\n");
    const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
    const char* src = text.c_str();
    glShaderSource(shader, 1, &src, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    auto log = [](GLuint obj, bool program) {
        GLint length = 0;
        program ? glGetProgramiv(obj, GL_INFO_LOG_LENGTH, &length) : glGetShaderiv(obj, GL_INFO_LOG_LENGTH, &length);
        std::vector<char> buf(static_cast<std::size_t>(length > 0 ? length : 1), '\0');
        program ? glGetProgramInfoLog(obj, length, nullptr, buf.data())
                : glGetShaderInfoLog(obj, length, nullptr, buf.data());
        return std::string(buf.data());
    };
    if (!ok) {
        const std::string message = log(shader, false);
        glDeleteShader(shader);
        throwRuntimeError("shaders/" + std::string(name) + " does not compile: " + message);
    }
    id_ = glCreateProgram();
    glAttachShader(id_, shader);
    glLinkProgram(id_);
    glDeleteShader(shader);
    glGetProgramiv(id_, GL_LINK_STATUS, &ok);
    if (!ok) throwRuntimeError("shaders/" + std::string(name) + " does not link: " + log(id_, true));
}

ComputeProgram::~ComputeProgram() {
    glDeleteProgram(id_);
}

void ComputeProgram::set(const char* uniform, int value) const {
    glProgramUniform1i(id_, glGetUniformLocation(id_, uniform), value);
}
void ComputeProgram::set(const char* uniform, float value) const {
    glProgramUniform1f(id_, glGetUniformLocation(id_, uniform), value);
}
void ComputeProgram::setDouble(const char* uniform, double value) const {
    glProgramUniform1d(id_, glGetUniformLocation(id_, uniform), value);
}

} // namespace ff::gpu
