#pragma once
// Display meshes of OpenSim models (docs/view.md): the triangles of a body's .vtp, .obj or .stl file,
// and the Mesh elements of an .osim that name them. Used only for drawing (`redmax view`); nothing
// in the dynamics reads geometry.
//
// Formats read:
//   .vtp  VTK XML PolyData (what OpenSim's Geometry folder holds): Points and Polys (triangles,
//         polygons fanned into triangles), DataArrays in `ascii`, inline `binary` (base64) or
//         `appended` (raw or base64) format, uncompressed or zlib-compressed (vtkZLibDataCompressor),
//         UInt32 or UInt64 headers, little-endian. Other compressors (LZ4, LZMA), big-endian data,
//         Strips, Lines and Verts are refused with the reason.
//   .obj  `v` and `f` lines (polygons fanned; `v/vt/vn` and negative indices taken).
//   .stl  ASCII or binary.
#include <string>
#include <vector>

#include "converter/model_description.hpp"

namespace redmax::osim {

/// Triangles: vertices x, y, z (m, in the mesh's own frame) and three vertex indices per triangle.
struct TriangleMesh {
  std::vector<double> vertices;  ///< 3 per vertex
  std::vector<int> triangles;    ///< 3 per triangle, 0-based
  int numVertices() const { return static_cast<int>(vertices.size() / 3); }
  int numTriangles() const { return static_cast<int>(triangles.size() / 3); }
};

/// Reads a mesh file by its extension (case-insensitive). Throws std::runtime_error saying why a
/// file cannot be read (missing, a format variant not read, an index out of range, no triangles).
TriangleMesh readMeshFile(const std::string& path);

/// One mesh attached to a body: OpenSim 4's <Mesh> (in a body's or an offset frame's
/// attached_geometry, or anywhere with a socket_frame), OpenSim 3's <VisibleObject>
/// geometry_files and <DisplayGeometry> geometry_file.
struct MeshAttachment {
  std::string body;               ///< body name, or the ground's name
  std::string mesh_file;          ///< as written (relative to the model's folder or its Geometry/)
  Vec3 scale = Vec3::Ones();      ///< scale_factors
  Mat4 X_body = Mat4::Identity(); ///< pose of the mesh frame in the body frame
  int line = 0;
};

/// The meshes the model file `d.source_file` names. A mesh whose frame cannot be placed on a body
/// is left out and named in `dropped` ("LINE: why").
std::vector<MeshAttachment> readMeshAttachments(const ModelDescription& d, std::vector<std::string>& dropped);

/// Where OpenSim looks for a mesh file of the model in `model_dir`: the file itself (absolute, or
/// relative to the model's folder), then `Geometry/` beside the model. "" when neither exists.
std::string findMeshFile(const std::string& model_dir, const std::string& mesh_file);

}  // namespace redmax::osim
