#pragma once
// The triangle surface every mesher in src/mesh makes and every pass edits, and the walk from a
// vertex to its triangles that the passes share (built once per state of the mesh they read).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

struct SurfaceMesh {
  std::vector<Vec3> vertices;                          // mm
  std::vector<std::array<std::int32_t, 3>> triangles;  // counter-clockwise seen from outside
  std::vector<std::int32_t> triangle_tree;             // the tree (forest index) of each triangle
  std::vector<float> vertex_step;                      // mm: the sampling step where each vertex was found
  std::vector<std::int32_t> triangle_face;             // empty, or per triangle: 0 the wall, k + 1 the cap of end k (vessel_ends.hpp)
};

// Each vertex's triangles, in increasing order (compressed rows). With `only`, the triangles of
// the vertices it marks (others have none): the passes that walk a small part of a large mesh.
class VertexTriangles {
 public:
  explicit VertexTriangles(const SurfaceMesh& m, const std::vector<char>* only = nullptr) : first_(m.vertices.size() + 1, 0) {
    const auto counted = [&](std::int32_t v) { return !only || (*only)[std::size_t(v)]; };
    for (const auto& t : m.triangles)
      for (auto v : t) first_[std::size_t(v) + 1] += counted(v);
    for (std::size_t v = 0; v + 1 < first_.size(); ++v) first_[v + 1] += first_[v];
    triangles_.resize(first_.back());
    std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
    for (std::size_t k = 0; k < m.triangles.size(); ++k)
      for (auto v : m.triangles[k])
        if (counted(v)) triangles_[fill[std::size_t(v)]++] = std::int32_t(k);
  }
  std::span<const std::int32_t> of(std::int32_t v) const {
    return {triangles_.data() + first_[std::size_t(v)], triangles_.data() + first_[std::size_t(v) + 1]};
  }

 private:
  std::vector<std::uint32_t> first_;
  std::vector<std::int32_t> triangles_;
};

}  // namespace angiosynth
