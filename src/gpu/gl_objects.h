#pragma once
// RAII owners of GL objects and GL error checking. They need the context current.

#include <epoxy/gl.h>

#include <cstddef>
#include <string>
#include <string_view>

namespace ff::gpu {

/// Work groups per dispatch dimension every GL 4.5 device allows.
constexpr GLuint kMaxWorkGroups = 65535;
/// Dispatches n work groups as a 1- or 2-D grid (x up to kMaxWorkGroups; the shaders fold y into one
/// index and skip the groups past n).
void dispatchGroups(GLuint n);

/// Throws ff::Error (Runtime) naming `what` if GL reports an error (with the driver's debug messages
/// in debug builds).
void checkGl(const char* what);
/// Keeps a driver debug message for the next checkGl (the debug callback of debug builds).
void recordDebugMessage(std::string message);

class Buffer {
  public:
    Buffer();
    ~Buffer();
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;
    /// (Re)allocates `bytes` and uploads `data` (may be null: uninitialised).
    void upload(const void* data, std::size_t bytes);
    /// Makes the buffer `bytes` long and all zero (keeps the storage when the size is unchanged).
    void zeros(std::size_t bytes);
    /// Zeroes `bytes` from `offset` (both multiples of 4, within the buffer).
    void zeros(std::size_t offset, std::size_t bytes);
    void download(void* data, std::size_t bytes) const;
    void bind(GLuint binding) const { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id_); }
    std::size_t bytes() const { return bytes_; }
    GLuint id() const { return id_; }

  private:
    GLuint id_ = 0;
    std::size_t bytes_ = 0;
};

/// A 2D RGB float32 texture, read by shaders with texelFetch.
class Texture {
  public:
    Texture();
    ~Texture();
    Texture(const Texture&) = delete;
    Texture& operator=(const Texture&) = delete;
    /// (Re)allocates width x height texels and uploads R, G, B interleaved rows.
    void upload(const float* rgb, int width, int height);
    void bind(GLuint unit) const { glBindTextureUnit(unit, id_); }

  private:
    GLuint id_ = 0;
    int width_ = 0, height_ = 0;
};

class ComputeProgram {
  public:
    /// Compiles `source` (a shader of shaders/, by name for messages) with LOCAL_SIZE defined.
    ComputeProgram(std::string_view name, std::string_view source, int localSize);
    ~ComputeProgram();
    ComputeProgram(const ComputeProgram&) = delete;
    ComputeProgram& operator=(const ComputeProgram&) = delete;
    void use() const { glUseProgram(id_); }
    void set(const char* uniform, int value) const;
    void set(const char* uniform, float value) const;
    void setDouble(const char* uniform, double value) const;
    int localSize() const { return localSize_; }

  private:
    GLuint id_ = 0;
    int localSize_ = 0;
};

} // namespace ff::gpu
