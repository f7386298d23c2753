#pragma once
/// Named, typed columns of equal length: the particle state and the frames of a stream.
/// A column holds n elements of `components` scalars of one type, stored contiguously and
/// 64-byte aligned, so a column of Vec3 can be viewed as Eigen::Vector3d*.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace mpm {

enum class ScalarType : std::uint8_t { F64 = 1, F32 = 2, U8 = 3, U32 = 4, I32 = 5, U64 = 6 };

/// Floating-point precision of the frames a run writes (output.precision).
enum class Precision { Float64, Float32 };

/// Size in bytes of one scalar of a type.
std::size_t scalar_size(ScalarType t);
/// Short name of a type: "f64", "f32", "u8", "u32", "i32", "u64".
const char* scalar_name(ScalarType t);

/// What a column holds.
struct ColumnInfo {
  std::string name;  ///< e.g. "x", "sigma", "eps_p"
  ScalarType type = ScalarType::F64;
  int components = 1;  ///< scalars per element (3 for a 3D vector, 6 for a Voigt tensor)
  std::string unit;    ///< SI unit for readers ("m", "Pa", "-")
  std::size_t element_bytes() const { return scalar_size(type) * components; }
};

/// One column: an aligned byte buffer viewed as n elements.
class Column {
 public:
  explicit Column(ColumnInfo info) : info_(std::move(info)) {}
  const ColumnInfo& info() const { return info_; }
  std::size_t size() const { return n_; }
  std::size_t bytes() const { return n_ * info_.element_bytes(); }
  /// Resizes to n elements; new elements are zero; existing ones are kept.
  void resize(std::size_t n);
  /// Reserves capacity for n elements.
  void reserve(std::size_t n);
  std::byte* data() { return data_.get(); }
  /// Bytes of storage held (capacity times the element size).
  std::size_t capacity_bytes() const { return capacity_ * info_.element_bytes(); }
  /// Deleter of column buffers (64-byte aligned).
  struct Free {
    void operator()(std::byte* p) const { ::operator delete[](p, std::align_val_t(64)); }
  };
  using Buffer = std::unique_ptr<std::byte[], Free>;
  /// Exchanges this column's storage with `buffer` of `buffer_bytes` bytes, which must hold
  /// size() elements; the column keeps its size and takes the buffer's contents.
  void swap_storage(Buffer& buffer, std::size_t& buffer_bytes);
  const std::byte* data() const { return data_.get(); }
  /// Typed view; T must have the size of one element (e.g. Eigen::Vector3d for 3 x f64).
  template <class T>
  T* as() {
    check_view(sizeof(T));
    return reinterpret_cast<T*>(data_.get());
  }
  template <class T>
  const T* as() const {
    check_view(sizeof(T));
    return reinterpret_cast<const T*>(data_.get());
  }

 private:
  void check_view(std::size_t bytes) const;
  ColumnInfo info_;
  std::size_t n_ = 0, capacity_ = 0;
  Buffer data_;
};

/// A set of columns of equal length.
class ColumnStore {
 public:
  std::size_t size() const { return n_; }
  /// Adds a column (zero-filled to the current size); throws if the name exists.
  Column& add(const ColumnInfo& info);
  /// The column of this name, or nullptr.
  Column* find(const std::string& name);
  const Column* find(const std::string& name) const;
  /// The column of this name; throws std::out_of_range naming it when absent.
  Column& at(const std::string& name);
  const Column& at(const std::string& name) const;
  bool has(const std::string& name) const { return find(name) != nullptr; }
  /// Typed pointer to a column's data; nullptr when the column is absent.
  template <class T>
  T* get(const std::string& name) {
    Column* c = find(name);
    return c ? c->as<T>() : nullptr;
  }
  template <class T>
  const T* get(const std::string& name) const {
    const Column* c = find(name);
    return c ? c->as<T>() : nullptr;
  }
  std::vector<Column>& columns() { return cols_; }
  const std::vector<Column>& columns() const { return cols_; }
  /// Resizes every column.
  void resize(std::size_t n);
  void reserve(std::size_t n);
  /// Reorders every column so that new element i is old element perm[i] (a gather).
  /// perm may be shorter than size() (elements not listed are dropped). Gathers each column
  /// into one spare buffer (widest columns first, so the spare always fits), which is swapped
  /// in when it has the column's size and copied back otherwise; the spare is as large as the
  /// widest column and is kept for the next call, and no column's storage ever grows.
  void gather(const std::vector<std::uint32_t>& perm);
  /// Bytes held by the columns (not counting scratch).
  std::size_t bytes() const;
  /// Bytes per element over all columns.
  std::size_t element_bytes() const;

 private:
  std::size_t n_ = 0;
  std::vector<Column> cols_;
  Column::Buffer spare_;
  std::size_t spare_bytes_ = 0;
};

}  // namespace mpm
