#include "core/mesh.h"

#include "core/test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rsibr {
namespace {

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

// The message of the std::runtime_error that load_mesh(path) throws ("" when it does not throw).
std::string load_error(const std::string& path) {
  try {
    load_mesh(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

void expect_one_line_naming(const std::string& message, const std::string& path) {
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

void expect_unit_normals(const Mesh& mesh) {
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (const auto& n : mesh.normals) ASSERT_NEAR(n.norm(), 1.0f, 1e-5f);
}

Eigen::Vector3f face_normal(const Mesh& mesh, std::size_t t) {
  const auto& tri = mesh.triangles[t];
  return (mesh.positions[tri[1]] - mesh.positions[tri[0]])
      .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]])
      .normalized();
}

// Fraction of triangles whose geometric (counter-clockwise) normal agrees with their vertex normals.
double front_facing_fraction(const Mesh& mesh) {
  std::size_t agree = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    for (uint32_t i : mesh.triangles[t]) sum += mesh.normals[i];
    if (sum.dot(face_normal(mesh, t)) > 0) ++agree;
  }
  return double(agree) / double(mesh.triangles.size());
}

// ---- real models (Draco-compressed .glb) ---------------------------------------------------------

struct RealModel {
  const char* name;
  std::size_t vertices, triangles;  // as stored in the file
  std::size_t degenerate;           // zero-area triangles stored in the file
  bool uvs;
};

class MeshRealModel : public ::testing::TestWithParam<RealModel> {};

TEST_P(MeshRealModel, LoadsWithExpectedCountsUnitNormalsAndFiniteBounds) {
  const RealModel& m = GetParam();
  const auto path = testing::assets_dir() / "models" / (std::string(m.name) + ".glb");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << testing::kNoAssets;
  MeshLoadReport report;
  const Mesh mesh = load_mesh(path.string(), &report);
  EXPECT_EQ(mesh.positions.size(), m.vertices);
  EXPECT_EQ(mesh.triangles.size(), m.triangles - m.degenerate);
  EXPECT_EQ(report.vertices, m.vertices);
  EXPECT_EQ(report.triangles, m.triangles - m.degenerate);
  EXPECT_EQ(report.dropped_degenerate, m.degenerate);
  EXPECT_FALSE(report.computed_normals);
  EXPECT_TRUE(report.draco);
  EXPECT_EQ(report.format, "glb");
  EXPECT_EQ(mesh.uvs.size(), m.uvs ? m.vertices : 0u);
  expect_unit_normals(mesh);
  for (const auto& t : mesh.triangles)
    for (uint32_t i : t) ASSERT_LT(i, mesh.positions.size());
  const Eigen::AlignedBox3f box = mesh.bounds();
  ASSERT_FALSE(box.isEmpty());
  EXPECT_TRUE(box.min().allFinite() && box.max().allFinite());
  EXPECT_GT(box.sizes().minCoeff(), 0.0f);
  // The file's normals agree with counter-clockwise winding almost everywhere.
  EXPECT_GT(front_facing_fraction(mesh), 0.95);
}

INSTANTIATE_TEST_SUITE_P(
    Mesh, MeshRealModel,
    // pmndrs stores one truly zero-area triangle (three collinear corners along z at x=-1.505, y=0.995).
    ::testing::Values(RealModel{"bunny", 2826, 5648, 0, false}, RealModel{"suzi", 7503, 14842, 0, false},
                      RealModel{"pmndrs", 1074, 1552, 1, true}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(MeshBunny, BoundsMatchTheAccessorMinMax) {
  const auto path = testing::assets_dir() / "models" / "bunny.glb";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << testing::kNoAssets;
  const Eigen::AlignedBox3f box = load_mesh(path.string()).bounds();
  // POSITION accessor min/max as written in the file (Draco quantisation keeps them within ~1e-3).
  EXPECT_TRUE(box.min().isApprox(Eigen::Vector3f(-0.91377f, -0.89104f, -0.69637f), 2e-3f)) << box.min().transpose();
  EXPECT_TRUE(box.max().isApprox(Eigen::Vector3f(0.91721f, 0.93988f, 0.69886f), 2e-3f)) << box.max().transpose();
}

// ---- OBJ -----------------------------------------------------------------------------------------

TEST(MeshObj, QuadAndTriangleWithoutNormalsGetComputedNormals) {
  testing::TempDir dir;
  const std::string path = dir.file("quad_tri.obj");
  write_text(path,
             "# a unit quad in z=0 and a triangle beside it\n"
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
             "f 1 2 3 4\n"
             "f 2 5 3\n");
  MeshLoadReport report;
  const Mesh mesh = load_mesh(path, &report);
  EXPECT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.positions.size(), 5u);
  EXPECT_TRUE(mesh.uvs.empty());
  EXPECT_TRUE(report.computed_normals);
  EXPECT_EQ(report.format, "obj");
  expect_unit_normals(mesh);
  for (const auto& n : mesh.normals) EXPECT_TRUE(n.isApprox(Eigen::Vector3f::UnitZ(), 1e-6f)) << n.transpose();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    EXPECT_TRUE(face_normal(mesh, t).isApprox(Eigen::Vector3f::UnitZ(), 1e-6f));
}

TEST(MeshObj, ComputedNormalsAreAreaWeighted) {
  // A big triangle in z=0 and a small one in x=0 share vertex 1; its normal leans to the big one.
  testing::TempDir dir;
  const std::string path = dir.file("tent.obj");
  write_text(path, "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 -1\nv 0 1 0\nf 1 2 3\nf 1 4 5\n");
  const Mesh mesh = load_mesh(path);
  const Eigen::Vector3f expected = Eigen::Vector3f(1.0f, 0.0f, 100.0f).normalized();  // areas 50 and 0.5
  EXPECT_TRUE(mesh.normals[0].isApprox(expected, 1e-5f)) << mesh.normals[0].transpose();
}

TEST(MeshObj, PerCornerNormalsSplitVerticesAndAreNormalised) {
  // Two faces of a cube edge: positions 2 and 3 are shared, normals differ per face.
  testing::TempDir dir;
  const std::string path = dir.file("edge.obj");
  write_text(path,
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 1 0 -1\nv 1 1 -1\n"
             "vn 0 0 2\nvn 3 0 0\n"
             "vt 0 0\nvt 1 0\nvt 1 1\n"
             "f 1/1/1 2/2/1 3/3/1\n"
             "f 2/1/2 4/2/2 5/3/2\n"
             "f 2/1/2 5/3/2 3/3/2\n");
  MeshLoadReport report;
  const Mesh mesh = load_mesh(path, &report);
  EXPECT_EQ(mesh.triangles.size(), 3u);
  // Vertices 2 and 3 appear with two normals each (and vertex 3 with one uv): 3 + 4 = 7 unique.
  EXPECT_EQ(mesh.positions.size(), 7u);
  EXPECT_FALSE(report.computed_normals);
  expect_unit_normals(mesh);
  for (uint32_t i : mesh.triangles[0]) EXPECT_TRUE(mesh.normals[i].isApprox(Eigen::Vector3f::UnitZ()));
  for (std::size_t t = 1; t < 3; ++t)
    for (uint32_t i : mesh.triangles[t]) EXPECT_TRUE(mesh.normals[i].isApprox(Eigen::Vector3f::UnitX()));
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  // OBJ's v runs up the image; Mesh's runs down (glTF convention).
  EXPECT_TRUE(mesh.uvs[mesh.triangles[0][0]].isApprox(Eigen::Vector2f(0, 1)));
  EXPECT_TRUE(mesh.uvs[mesh.triangles[0][2]].isApprox(Eigen::Vector2f(1, 0)));
}

TEST(MeshObj, DegenerateTrianglesAreDroppedAndCounted) {
  testing::TempDir dir;
  const std::string path = dir.file("degenerate.obj");
  write_text(path,
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
             "f 1 2 3\n"
             "f 1 2 4\n"    // collinear: zero area
             "f 1 1 3\n");  // repeated corner
  MeshLoadReport report;
  const Mesh mesh = load_mesh(path, &report);
  EXPECT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(report.triangles, 1u);
  EXPECT_EQ(report.dropped_degenerate, 2u);
}

TEST(MeshObj, OnlyDegenerateTrianglesIsAnError) {
  testing::TempDir dir;
  const std::string path = dir.file("flat.obj");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  const std::string msg = load_error(path);
  expect_one_line_naming(msg, path);
  EXPECT_NE(msg.find("no triangles"), std::string::npos) << msg;
}

TEST(MeshObj, OutOfRangeIndexIsAOneLineError) {
  testing::TempDir dir;
  const std::string path = dir.file("bad_index.obj");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  const std::string msg = load_error(path);
  expect_one_line_naming(msg, path);
  EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

// ---- errors --------------------------------------------------------------------------------------

TEST(MeshErrors, MissingFileNamesTheFile) {
  testing::TempDir dir;
  const std::string path = dir.file("absent.glb");
  const std::string msg = load_error(path);
  expect_one_line_naming(msg, path);
  EXPECT_NE(msg.find("no such file"), std::string::npos) << msg;
}

TEST(MeshErrors, UnsupportedExtensionNamesTheFile) {
  testing::TempDir dir;
  const std::string path = dir.file("model.ply");
  write_text(path, "ply\n");
  const std::string msg = load_error(path);
  expect_one_line_naming(msg, path);
  EXPECT_NE(msg.find("unsupported"), std::string::npos) << msg;
}

TEST(MeshErrors, GarbageFilesAreOneLineErrors) {
  testing::TempDir dir;
  std::vector<unsigned char> junk(4096);
  uint32_t x = 12345;
  for (auto& b : junk) b = static_cast<unsigned char>((x = x * 1664525u + 1013904223u) >> 24);
  for (const char* name : {"junk.glb", "junk.gltf", "junk.obj"}) {
    const std::string path = dir.file(name);
    write_bytes(path, junk);
    const std::string msg = load_error(path);
    ASSERT_FALSE(msg.empty()) << name;
    expect_one_line_naming(msg, path);
  }
  // A GLB header followed by nonsense JSON.
  const std::string path = dir.file("bad_json.glb");
  std::vector<unsigned char> glb = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 28, 0, 0, 0, 8, 0, 0, 0, 'J', 'S', 'O', 'N'};
  for (char c : std::string("{nope!!}")) glb.push_back(static_cast<unsigned char>(c));
  write_bytes(path, glb);
  const std::string msg = load_error(path);
  expect_one_line_naming(msg, path);
}

// ---- uncompressed glTF ---------------------------------------------------------------------------

// One triangle (0,0,0), (1,0,0), (0,1,0) facing +Z: positions (36 bytes), optionally normals
// (36 bytes), then uint16 indices (6 bytes + 2 padding).
std::vector<unsigned char> triangle_buffer(bool normals, uint16_t last_index = 2) {
  std::vector<float> f = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  if (normals) f.insert(f.end(), {0, 0, 1, 0, 0, 1, 0, 0, 1});
  std::vector<unsigned char> out(f.size() * 4);
  std::memcpy(out.data(), f.data(), out.size());
  for (uint16_t i : {uint16_t(0), uint16_t(1), last_index}) {
    out.push_back(static_cast<unsigned char>(i & 0xff));
    out.push_back(static_cast<unsigned char>(i >> 8));
  }
  out.push_back(0);
  out.push_back(0);
  return out;
}

// Nodes: 0 translates by (10,0,0) and has child 1 (rotation of 90 degrees about +Y, as a matrix);
// 2 mirrors x (scale -1,1,1). All three instance mesh 0.
std::string triangle_json(bool normals, std::size_t buffer_bytes, const std::string& buffer_uri) {
  const std::string uri = buffer_uri.empty() ? "" : "\"uri\": \"" + buffer_uri + "\", ";
  std::string attributes = normals ? "{\"POSITION\": 0, \"NORMAL\": 2}" : "{\"POSITION\": 0}";
  const std::size_t index_offset = normals ? 72 : 36;
  std::string json =
      "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 2]}],"
      "\"nodes\": ["
      "{\"mesh\": 0, \"translation\": [10, 0, 0], \"children\": [1]},"
      "{\"mesh\": 0, \"matrix\": [0,0,-1,0, 0,1,0,0, 1,0,0,0, 0,0,0,1]},"
      "{\"mesh\": 0, \"scale\": [-1, 1, 1]}],"
      "\"meshes\": [{\"primitives\": [{\"attributes\": " +
      attributes +
      ", \"indices\": 1, \"mode\": 4}]}],"
      "\"buffers\": [{" +
      uri + "\"byteLength\": " + std::to_string(buffer_bytes) +
      "}],"
      "\"bufferViews\": ["
      "{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 36},"
      "{\"buffer\": 0, \"byteOffset\": " +
      std::to_string(index_offset) + ", \"byteLength\": 6}" +
      (normals ? ", {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 36}" : "") +
      "],"
      "\"accessors\": ["
      "{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\","
      " \"min\": [0,0,0], \"max\": [1,1,0]},"
      "{\"bufferView\": 1, \"componentType\": 5123, \"count\": 3, \"type\": \"SCALAR\"}" +
      (normals ? ", {\"bufferView\": 2, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}" : "") + "]}";
  return json;
}

void append_u32(std::vector<unsigned char>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

std::vector<unsigned char> make_glb(std::string json, const std::vector<unsigned char>& bin) {
  while (json.size() % 4) json += ' ';
  std::vector<unsigned char> out;
  append_u32(out, 0x46546C67u);
  append_u32(out, 2);
  append_u32(out, uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  append_u32(out, uint32_t(json.size()));
  append_u32(out, 0x4E4F534Au);
  out.insert(out.end(), json.begin(), json.end());
  append_u32(out, uint32_t(bin.size()));
  append_u32(out, 0x004E4942u);
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

// The three instances of the +Z triangle, as placed by triangle_json's nodes.
void expect_three_placed_triangles(const Mesh& mesh) {
  ASSERT_EQ(mesh.triangles.size(), 3u);
  ASSERT_EQ(mesh.positions.size(), 9u);
  expect_unit_normals(mesh);
  // Node 0: translated by +10 x.
  EXPECT_TRUE(mesh.positions[1].isApprox(Eigen::Vector3f(11, 0, 0)));
  EXPECT_TRUE(mesh.normals[0].isApprox(Eigen::Vector3f::UnitZ()));
  // Node 1 (child of 0): rotated 90 degrees about +Y (x -> -z, z -> x), then translated.
  EXPECT_TRUE(mesh.positions[4].isApprox(Eigen::Vector3f(10, 0, -1))) << mesh.positions[4].transpose();
  EXPECT_TRUE(mesh.normals[3].isApprox(Eigen::Vector3f::UnitX())) << mesh.normals[3].transpose();
  // Node 2: mirrored in x; the winding is flipped so the front face still matches the normal.
  EXPECT_TRUE(mesh.positions[7].isApprox(Eigen::Vector3f(-1, 0, 0)));
  EXPECT_TRUE(mesh.normals[6].isApprox(Eigen::Vector3f::UnitZ())) << mesh.normals[6].transpose();
  for (std::size_t t = 0; t < 3; ++t)
    EXPECT_TRUE(face_normal(mesh, t).isApprox(mesh.normals[mesh.triangles[t][0]], 1e-5f)) << "triangle " << t;
}

TEST(MeshGltf, UncompressedGltfWithExternalBufferAppliesNodeTransforms) {
  testing::TempDir dir;
  const auto bin = triangle_buffer(true);
  write_bytes(dir.file("tri.bin"), bin);
  const std::string path = dir.file("tri.gltf");
  write_text(path, triangle_json(true, bin.size(), "tri.bin"));
  MeshLoadReport report;
  const Mesh mesh = load_mesh(path, &report);
  EXPECT_EQ(report.format, "gltf");
  EXPECT_FALSE(report.draco);
  EXPECT_FALSE(report.computed_normals);
  expect_three_placed_triangles(mesh);
}

TEST(MeshGltf, UncompressedGlbWithoutNormalsComputesThem) {
  testing::TempDir dir;
  const auto bin = triangle_buffer(false);
  const std::string path = dir.file("tri.glb");
  write_bytes(path, make_glb(triangle_json(false, bin.size(), ""), bin));
  MeshLoadReport report;
  const Mesh mesh = load_mesh(path, &report);
  EXPECT_EQ(report.format, "glb");
  EXPECT_TRUE(report.computed_normals);
  expect_three_placed_triangles(mesh);
}

TEST(MeshGltf, OutOfRangeIndexIsAOneLineError) {
  testing::TempDir dir;
  const auto bin = triangle_buffer(false, 7);
  const std::string path = dir.file("bad_index.glb");
  write_bytes(path, make_glb(triangle_json(false, bin.size(), ""), bin));
  const std::string msg = load_error(path);
  expect_one_line_naming(msg, path);
  EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
}

TEST(MeshGltf, NonFinitePositionIsAOneLineError) {
  testing::TempDir dir;
  auto bin = triangle_buffer(false);
  const float nan = std::nanf("");
  std::memcpy(bin.data() + 4, &nan, 4);  // y of the first vertex
  const std::string path = dir.file("nan.glb");
  write_bytes(path, make_glb(triangle_json(false, bin.size(), ""), bin));
  const std::string msg = load_error(path);
  expect_one_line_naming(msg, path);
  EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;
}

TEST(MeshGltf, TruncatedBufferIsAOneLineError) {
  testing::TempDir dir;
  auto bin = triangle_buffer(true);
  write_bytes(dir.file("short.bin"), std::vector<unsigned char>(bin.begin(), bin.begin() + 20));
  const std::string path = dir.file("short.gltf");
  write_text(path, triangle_json(true, bin.size(), "short.bin"));
  const std::string msg = load_error(path);
  ASSERT_FALSE(msg.empty());
  expect_one_line_naming(msg, path);
}

TEST(MeshBounds, EmptyMeshHasEmptyBounds) { EXPECT_TRUE(Mesh{}.bounds().isEmpty()); }

}  // namespace
}  // namespace rsibr
