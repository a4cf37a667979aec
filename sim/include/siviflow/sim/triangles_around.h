// The triangles around each vertex of a triangle mesh, each vertex's in ascending order: what
// a river keeps to gather a node's velocity and a vertex's one-ring. A long river keeps them for
// its whole life, so they are held in 1 or 2 bytes a triangle where the mesh's order allows it:
// each as its offset from where the vertex's triangles would start were the triangles numbered
// in the order of their vertices (v * T / V). A river mesh is laid out section after section, so
// the offsets stay small (1 byte while a section is narrower than about 60 vertices); a mesh
// whose order is far from that keeps 4 bytes a triangle.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <span>
#include <vector>

namespace siviflow {

class TrianglesAround {
  // Every vertex's list, end to end, in whichever of the three widths holds them.
  struct Lists {
    const int8_t* offsets8 = nullptr;     // triangle = anchor + offset
    const int16_t* offsets16 = nullptr;   // the same, where 1 byte does not reach
    const uint32_t* triangles = nullptr;  // else the triangles themselves
    uint32_t at(size_t i, int64_t anchor) const {
      if (offsets8 != nullptr) return static_cast<uint32_t>(anchor + offsets8[i]);
      if (offsets16 != nullptr) return static_cast<uint32_t>(anchor + offsets16[i]);
      return triangles[i];
    }
  };

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
      Iterator(const Lists& lists, size_t at, int64_t anchor)
          : lists_(lists), at_(at), anchor_(anchor) {}
      uint32_t operator*() const { return lists_.at(at_, anchor_); }
      Iterator& operator++() {
        ++at_;
        return *this;
      }
      Iterator operator++(int) {
        const Iterator before = *this;
        ++*this;
        return before;
      }
      bool operator==(const Iterator& other) const { return at_ == other.at_; }

     private:
      Lists lists_;
      size_t at_ = 0;
      int64_t anchor_ = 0;
    };

    Range(const Lists& lists, size_t first, size_t size, int64_t anchor)
        : lists_(lists), first_(first), size_(size), anchor_(anchor) {}
    uint32_t operator[](size_t i) const { return lists_.at(first_ + i, anchor_); }
    size_t size() const { return size_; }
    Iterator begin() const { return {lists_, first_, anchor_}; }
    Iterator end() const { return {lists_, first_ + size_, anchor_}; }

   private:
    Lists lists_;
    size_t first_;
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
    return Range(lists(), first, size, compact() ? anchor(v) : 0);
  }
  // Whether they are held in 1 or 2 bytes a triangle, and in how many.
  bool compact() const { return offset_bytes() != 0; }
  int offset_bytes() const { return !offsets8_.empty() ? 1 : !offsets16_.empty() ? 2 : 0; }
  size_t memory_bytes() const;

 private:
  int64_t anchor(uint32_t v) const {
    return static_cast<int64_t>(uint64_t{v} * triangle_count_ / vertex_count());
  }
  Lists lists() const {
    return {offsets8_.empty() ? nullptr : offsets8_.data(),
            offsets16_.empty() ? nullptr : offsets16_.data(),
            triangles_.empty() ? nullptr : triangles_.data()};
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
  std::vector<int8_t> offsets8_;          // where every offset fits
  std::vector<int16_t> offsets16_;        // else where these do
  std::vector<uint32_t> triangles_;  // only when not compact
  uint64_t triangle_count_ = 0;
};

}  // namespace siviflow
