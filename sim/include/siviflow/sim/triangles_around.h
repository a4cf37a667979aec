// The triangles around each vertex of a triangle mesh, each vertex's in ascending order: what
// a river keeps to gather a node's velocity and a vertex's one-ring. A long river keeps them for
// its whole life, so they are held in 2 bytes a triangle where the mesh's order allows it: each
// as its offset from where the vertex's triangles would start were the triangles numbered in
// the order of their vertices (v * T / V). A river mesh is laid out section after section, so
// the offsets stay small; a mesh whose order is far from that keeps 4 bytes a triangle.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <span>
#include <vector>

namespace siviflow {

class TrianglesAround {
 public:
  // One vertex's triangles, ascending. Its iterators stay valid while the TrianglesAround does.
  class Range {
   public:
    class Iterator {
     public:
      using iterator_category = std::forward_iterator_tag;
      using value_type = uint32_t;
      using difference_type = std::ptrdiff_t;
      using pointer = void;
      using reference = uint32_t;

      Iterator() = default;
      Iterator(const int16_t* offset, const uint32_t* triangle, int64_t anchor)
          : offset_(offset), triangle_(triangle), anchor_(anchor) {}
      uint32_t operator*() const {
        return offset_ != nullptr ? static_cast<uint32_t>(anchor_ + *offset_) : *triangle_;
      }
      Iterator& operator++() {
        if (offset_ != nullptr) {
          ++offset_;
        } else {
          ++triangle_;
        }
        return *this;
      }
      Iterator operator++(int) {
        const Iterator before = *this;
        ++*this;
        return before;
      }
      bool operator==(const Iterator& other) const = default;

     private:
      const int16_t* offset_ = nullptr;     // compact: triangle = anchor + offset
      const uint32_t* triangle_ = nullptr;  // else the triangle itself
      int64_t anchor_ = 0;
    };

    Range(const int16_t* offsets, const uint32_t* triangles, size_t size, int64_t anchor)
        : offsets_(offsets), triangles_(triangles), size_(size), anchor_(anchor) {}
    uint32_t operator[](size_t i) const {
      return offsets_ != nullptr ? static_cast<uint32_t>(anchor_ + offsets_[i]) : triangles_[i];
    }
    size_t size() const { return size_; }
    Iterator begin() const { return {offsets_, triangles_, anchor_}; }
    Iterator end() const {
      return offsets_ != nullptr ? Iterator(offsets_ + size_, nullptr, anchor_)
                                 : Iterator(nullptr, triangles_ + size_, anchor_);
    }

   private:
    const int16_t* offsets_;     // compact: triangle = anchor + offset
    const uint32_t* triangles_;  // else the triangles themselves
    size_t size_;
    int64_t anchor_;
  };

  // Counted from a mesh of `vertex_count` vertices: `indices` holds 3 per triangle, or is empty
  // when every 3 vertices are a triangle. Every index must be below `vertex_count`.
  static TrianglesAround of_mesh(size_t vertex_count, std::span<const uint32_t> indices);

  size_t vertex_count() const { return vertex_count_; }
  size_t triangle_count() const { return triangle_count_; }
  Range of(uint32_t v) const {
    const size_t first = start(v), size = start(size_t{v} + 1) - first;
    return offsets_.empty() ? Range(nullptr, triangles_.data() + first, size, 0)
                            : Range(offsets_.data() + first, nullptr, size, anchor(v));
  }
  // Whether they are held in 2 bytes a triangle.
  bool compact() const { return !offsets_.empty(); }
  size_t memory_bytes() const;

 private:
  int64_t anchor(uint32_t v) const {
    return static_cast<int64_t>(uint64_t{v} * triangle_count_ / vertex_count());
  }
  // Where vertex v's triangles start in the lists (v = vertex_count(): their end).
  size_t start(size_t v) const {
    return start_.empty() ? size_t{block_start_[v >> kBlockShift]} + start_in_block_[v] : start_[v];
  }
  // Where each vertex's triangles start, in 2 bytes a vertex: from its block of 256 vertices'
  // start. If any vertex starts more than 65535 entries past its block's start, every vertex's
  // start is kept in 4 bytes.
  static constexpr size_t kBlockShift = 8;
  void compact_starts(std::vector<uint32_t>* starts);

  size_t vertex_count_ = 0;
  std::vector<uint32_t> block_start_;     // per block of vertices 0..vertex_count()
  std::vector<uint16_t> start_in_block_;  // per vertex and the end
  std::vector<uint32_t> start_;           // only where the blocks' offsets do not fit
  std::vector<int16_t> offsets_;
  std::vector<uint32_t> triangles_;  // only when not compact
  uint64_t triangle_count_ = 0;
};

}  // namespace siviflow
