// A Wavefront OBJ's triangles, for the view page (camproj/view.h).
#ifndef CAMPROJ_SRC_VIEW_OBJ_MESH_H_
#define CAMPROJ_SRC_VIEW_OBJ_MESH_H_

#include <cstdint>
#include <string>
#include <vector>

namespace camproj::internal {

struct ObjMesh {
  std::vector<double> positions;   // x, y, z per vertex, world units
  std::vector<uint32_t> triangles; // 3 vertex indices (0-based) per triangle; polygons as fans
};

constexpr size_t kMaxObjElements = 5'000'000;  // vertices, and triangles

// Reads `v x y z [w]` and `f i[/t[/n]] ...` lines (1-based or negative relative indices); other
// lines are ignored. `source` names the text in messages. Throws InputError naming the source and
// line: a coordinate that is not a finite number, an index of 0 or out of range, a face of fewer
// than 3 vertices, more than kMaxObjElements vertices or triangles.
ObjMesh ParseObjMesh(const std::string& text, const std::string& source);

}  // namespace camproj::internal

#endif  // CAMPROJ_SRC_VIEW_OBJ_MESH_H_
