// The vertex positions of a PLY file (private; `camproj fit --bounds-mesh model.ply`): the header
// (`ply`, `format ascii 1.0 | binary_little_endian 1.0 | binary_big_endian 1.0`, `element`,
// `property`, `end_header`), then the x, y, z of the `vertex` element, whatever other properties
// it has and wherever it comes among the elements (those before it are read past, lists included).
#ifndef CAMPROJ_SRC_VIEW_PLY_VERTICES_H_
#define CAMPROJ_SRC_VIEW_PLY_VERTICES_H_

#include <string>
#include <vector>

#include <Eigen/Core>

namespace camproj {
namespace internal {

// Throws InputError naming `source` and what is wrong: not a PLY file, an unknown format or
// property type, no vertex element or no x, y or z property, data cut short, a coordinate that is
// not a finite number, more than 50 000 000 vertices.
std::vector<Eigen::Vector3d> PlyVertexPositions(const std::string& bytes, const std::string& source);

}  // namespace internal
}  // namespace camproj

#endif  // CAMPROJ_SRC_VIEW_PLY_VERTICES_H_
