// Mesh loading: shared validation and normals, the .obj reader (tinyobjloader) and the glTF
// reader (tinygltf + Draco).
//
// Wiring: Debian ships tinyobjloader and tinygltf as compiled shared libraries (libtinyobjloader,
// libtinygltf, the latter built with stb_image/nlohmann json inside), so neither
// TINYOBJLOADER_IMPLEMENTATION nor TINYGLTF_IMPLEMENTATION is defined here. tinygltf 2.7 is built
// without Draco: it ignores extensionsRequired, but refuses a primitive whose index accessor has
// no bufferView ("accessor[0] invalid bufferView"), which is exactly how a Draco primitive looks.
// So the JSON is patched before tinygltf sees it (the `indices` of Draco primitives are removed;
// the indices come from the Draco stream), and the Draco buffer view is decoded here.
#include "core/mesh.h"

#include "formats/file_error.h"
#include "formats/input_file.h"

#include "core/text.h"

#include <draco/compression/decode.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

namespace rsibr {

Eigen::AlignedBox3f Mesh::bounds() const {
  Eigen::AlignedBox3f box;  // empty
  for (const auto& p : positions) box.extend(p);
  return box;
}

void compute_vertex_normals(Mesh& mesh, const std::vector<bool>& needs) {
  const std::size_t n = mesh.positions.size();
  std::vector<Eigen::Vector3d> acc(n, Eigen::Vector3d::Zero());
  // The cross product of two edges has length twice the triangle's area, so summing unnormalised
  // face normals weights each face by its area.
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.positions[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.positions[t[2]].cast<double>();
    const Eigen::Vector3d f = (b - a).cross(c - a);
    for (uint32_t i : t) acc[i] += f;
  }
  mesh.normals.resize(n, Eigen::Vector3f::UnitY());
  for (std::size_t i = 0; i < n; ++i) {
    if (!needs.empty() && !needs[i]) continue;
    const double len = acc[i].norm();
    mesh.normals[i] = len > 0 && std::isfinite(len) ? (acc[i] / len).cast<float>().eval() : Eigen::Vector3f::UnitY();
  }
}

namespace {

void finalize_mesh(Mesh& mesh, std::vector<bool>& has_normal, MeshLoadReport& report) {
  const std::size_t n = mesh.positions.size();
  if (mesh.normals.size() != n) mesh.normals.resize(n, Eigen::Vector3f::Zero());
  has_normal.resize(n, false);
  if (!mesh.uvs.empty() && mesh.uvs.size() != n) mesh.uvs.clear();

  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t i : mesh.triangles[t])
      if (i >= n)
        throw std::runtime_error("triangle " + std::to_string(t) + " has vertex index " + std::to_string(i) +
                                 " out of range (" + std::to_string(n) + " vertices)");
  for (std::size_t i = 0; i < n; ++i)
    if (!mesh.positions[i].allFinite())
      throw std::runtime_error("vertex " + std::to_string(i) + " has a non-finite position");

  // Zero-area triangles: a repeated index, or edges whose cross product vanishes relative to the
  // edge lengths (collinear corners, to float precision).
  std::size_t kept = 0;
  for (const auto& t : mesh.triangles) {
    bool degenerate = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    if (!degenerate) {
      const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
      const Eigen::Vector3d e1 = mesh.positions[t[1]].cast<double>() - a;
      const Eigen::Vector3d e2 = mesh.positions[t[2]].cast<double>() - a;
      const double scale = std::max(e1.squaredNorm(), e2.squaredNorm());
      degenerate = !(e1.cross(e2).norm() > 1e-12 * scale);
    }
    if (degenerate) {
      ++report.dropped_degenerate;
    } else {
      mesh.triangles[kept++] = t;
    }
  }
  mesh.triangles.resize(kept);
  if (mesh.triangles.empty()) {
    throw std::runtime_error(report.dropped_degenerate
                                 ? "no triangles (all " + std::to_string(report.dropped_degenerate) + " are degenerate)"
                                 : "no triangles");
  }

  // File normals: normalised; zero or non-finite ones are recomputed like missing ones.
  std::vector<bool> needs(n, false);
  bool any = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (has_normal[i]) {
      const float len = mesh.normals[i].norm();
      if (len > 0 && std::isfinite(len)) {
        mesh.normals[i] /= len;
        continue;
      }
    }
    needs[i] = true;
    any = true;
  }
  if (any) {
    compute_vertex_normals(mesh, needs);
    report.computed_normals = true;
  }
  report.vertices = n;
  report.triangles = mesh.triangles.size();
}

Mesh load_obj(const std::string& path, MeshLoadReport& report) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = std::filesystem::path(path).parent_path().string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    const std::string err = one_line(reader.Error());
    throw std::runtime_error(err.empty() ? "cannot parse OBJ" : "OBJ: " + err);
  }
  const auto& attrib = reader.GetAttrib();
  const std::size_t nv = attrib.vertices.size() / 3, nn = attrib.normals.size() / 3, nt = attrib.texcoords.size() / 2;

  Mesh mesh;
  std::vector<bool> has_normal;
  bool all_uv = true;
  // One output vertex per distinct (position, normal, uv) index triple.
  struct Key {
    int v, n, t;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return std::hash<uint64_t>()((uint64_t(uint32_t(k.v)) << 32) ^ (uint64_t(uint32_t(k.n)) << 16) ^
                                   uint64_t(uint32_t(k.t)) * 0x9E3779B97F4A7C15ull);
    }
  };
  std::unordered_map<Key, uint32_t, KeyHash> ids;
  auto vertex = [&](const tinyobj::index_t& ix) -> uint32_t {
    const Key key{ix.vertex_index, ix.normal_index, ix.texcoord_index};
    if (auto it = ids.find(key); it != ids.end()) return it->second;
    if (ix.vertex_index < 0 || std::size_t(ix.vertex_index) >= nv)
      throw std::runtime_error("face refers to vertex " + std::to_string(ix.vertex_index + 1) + " out of range (" +
                               std::to_string(nv) + " vertices)");
    if (ix.normal_index >= 0 && std::size_t(ix.normal_index) >= nn)
      throw std::runtime_error("face refers to normal " + std::to_string(ix.normal_index + 1) + " out of range (" +
                               std::to_string(nn) + " normals)");
    if (ix.texcoord_index >= 0 && std::size_t(ix.texcoord_index) >= nt)
      throw std::runtime_error("face refers to texture coordinate " + std::to_string(ix.texcoord_index + 1) +
                               " out of range (" + std::to_string(nt) + " texture coordinates)");
    const auto id = uint32_t(mesh.positions.size());
    const float* p = &attrib.vertices[3 * std::size_t(ix.vertex_index)];
    mesh.positions.emplace_back(p[0], p[1], p[2]);
    if (ix.normal_index >= 0) {
      const float* q = &attrib.normals[3 * std::size_t(ix.normal_index)];
      mesh.normals.emplace_back(q[0], q[1], q[2]);
      has_normal.push_back(true);
    } else {
      mesh.normals.emplace_back(Eigen::Vector3f::Zero());
      has_normal.push_back(false);
    }
    if (ix.texcoord_index >= 0) {
      const float* q = &attrib.texcoords[2 * std::size_t(ix.texcoord_index)];
      mesh.uvs.emplace_back(q[0], 1.0f - q[1]);
    } else {
      mesh.uvs.emplace_back(Eigen::Vector2f::Zero());
      all_uv = false;
    }
    ids.emplace(key, id);
    return id;
  };

  for (const auto& shape : reader.GetShapes()) {
    std::size_t offset = 0;
    for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const std::size_t fv = shape.mesh.num_face_vertices[f];
      if (offset + fv > shape.mesh.indices.size()) throw std::runtime_error("OBJ: face index list is truncated");
      // tinyobjloader has triangulated polygons already; a fan covers anything it left.
      for (std::size_t k = 2; k < fv; ++k) {
        const uint32_t a = vertex(shape.mesh.indices[offset]);
        const uint32_t b = vertex(shape.mesh.indices[offset + k - 1]);
        const uint32_t c = vertex(shape.mesh.indices[offset + k]);
        mesh.triangles.push_back({a, b, c});
      }
      offset += fv;
    }
  }
  if (!all_uv) mesh.uvs.clear();
  finalize_mesh(mesh, has_normal, report);
  return mesh;
}

// ---- glTF ---------------------------------------------------------------------------------------

std::vector<unsigned char> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open file");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("read error");
  return bytes;
}

uint32_t read_u32(const unsigned char* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);  // glTF is little-endian, as is every platform we build for
  return v;
}

void append_u32(std::vector<unsigned char>& out, uint32_t v) {
  unsigned char b[4];
  std::memcpy(b, &v, 4);
  out.insert(out.end(), b, b + 4);
}

// Removes `indices` from primitives compressed with KHR_draco_mesh_compression (see the top of
// this file). Returns the JSON text unchanged when there is nothing to patch.
std::string patch_draco_json(const std::string& text) {
  nlohmann::json doc = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) throw std::runtime_error("malformed glTF JSON");
  bool changed = false;
  if (auto meshes = doc.find("meshes"); meshes != doc.end() && meshes->is_array()) {
    for (auto& m : *meshes) {
      if (!m.is_object() || !m.contains("primitives") || !m["primitives"].is_array()) continue;
      for (auto& prim : m["primitives"]) {
        if (!prim.is_object() || !prim.contains("extensions") || !prim["extensions"].is_object()) continue;
        if (!prim["extensions"].contains("KHR_draco_mesh_compression")) continue;
        if (prim.erase("indices")) changed = true;
      }
    }
  }
  return changed ? doc.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) : text;
}

bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;  // textures are not part of a Mesh; leave them undecoded
}

tinygltf::Model parse_gltf(const std::string& path, bool binary) {
  const std::vector<unsigned char> bytes = read_bytes(path);
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&skip_image, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const std::string base_dir = std::filesystem::path(path).parent_path().string();
  bool ok = false;
  if (binary) {
    // GLB: 12-byte header (magic, version, length), then a JSON chunk and an optional BIN chunk.
    if (bytes.size() < 20 || read_u32(bytes.data()) != 0x46546C67u)
      throw std::runtime_error("not a binary glTF file (bad magic)");
    if (read_u32(bytes.data() + 4) != 2)
      throw std::runtime_error("unsupported binary glTF version " + std::to_string(read_u32(bytes.data() + 4)));
    const uint32_t json_len = read_u32(bytes.data() + 12);
    if (read_u32(bytes.data() + 16) != 0x4E4F534Au || json_len > bytes.size() - 20)
      throw std::runtime_error("malformed binary glTF (bad JSON chunk)");
    const std::string json_text(reinterpret_cast<const char*>(bytes.data() + 20), json_len);
    std::string patched = patch_draco_json(json_text);
    std::vector<unsigned char> glb;
    const std::vector<unsigned char>* input = &bytes;
    if (patched != json_text) {
      while (patched.size() % 4) patched += ' ';
      const std::size_t rest = 20 + ((std::size_t(json_len) + 3) & ~std::size_t(3));
      glb.reserve(bytes.size() + patched.size());
      append_u32(glb, 0x46546C67u);
      append_u32(glb, 2);
      append_u32(glb, 0);  // total length, below
      append_u32(glb, uint32_t(patched.size()));
      append_u32(glb, 0x4E4F534Au);
      glb.insert(glb.end(), patched.begin(), patched.end());
      if (rest < bytes.size()) glb.insert(glb.end(), bytes.begin() + std::ptrdiff_t(rest), bytes.end());
      const auto total = uint32_t(glb.size());
      std::memcpy(glb.data() + 8, &total, 4);
      input = &glb;
    }
    ok = loader.LoadBinaryFromMemory(&model, &err, &warn, input->data(), unsigned(input->size()), base_dir);
  } else {
    const std::string text = patch_draco_json(std::string(bytes.begin(), bytes.end()));
    ok = loader.LoadASCIIFromString(&model, &err, &warn, text.data(), unsigned(text.size()), base_dir);
  }
  if (!ok) throw std::runtime_error("glTF: " + (err.empty() ? std::string("cannot parse") : one_line(err)));
  for (const auto& ext : model.extensionsRequired)
    if (ext != "KHR_draco_mesh_compression")
      throw std::runtime_error("glTF requires extension " + ext + ", which is not supported");
  return model;
}

// One primitive's vertices and triangles, before the node transform.
struct PrimitiveData {
  std::vector<float> positions, normals, uvs;  // 3, 3, 2 floats per vertex (normals/uvs may be empty)
  std::vector<uint32_t> indices;               // as stored; empty means 0..n-1
};

float component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = static_cast<int8_t>(*p);
      return normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(*p) / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? float(v) / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return normalized ? float(double(v) / 4294967295.0) : float(v);
    }
    default: throw std::runtime_error("unsupported accessor component type " + std::to_string(type));
  }
}

// The bytes of accessor `index`, checked against its buffer view and buffer.
struct AccessorView {
  const unsigned char* data = nullptr;  // null: all zeros (no bufferView)
  std::size_t count = 0, stride = 0, element = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
};

AccessorView view_accessor(const tinygltf::Model& model, int index, const std::string& what) {
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    throw std::runtime_error(what + " accessor " + std::to_string(index) + " out of range");
  const auto& acc = model.accessors[std::size_t(index)];
  if (acc.sparse.isSparse)
    throw std::runtime_error(what + " accessor " + std::to_string(index) + " is sparse (not supported)");
  AccessorView v;
  v.count = acc.count;
  v.component_type = acc.componentType;
  v.normalized = acc.normalized;
  v.components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
  const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
  if (v.components <= 0 || csize <= 0)
    throw std::runtime_error(what + " accessor " + std::to_string(index) + " has an invalid type");
  v.element = std::size_t(v.components) * std::size_t(csize);
  if (acc.bufferView < 0) return v;
  if (std::size_t(acc.bufferView) >= model.bufferViews.size())
    throw std::runtime_error(what + " accessor " + std::to_string(index) + " has an invalid bufferView");
  const auto& bv = model.bufferViews[std::size_t(acc.bufferView)];
  if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
    throw std::runtime_error("bufferView " + std::to_string(acc.bufferView) + " has an invalid buffer");
  const auto& buf = model.buffers[std::size_t(bv.buffer)];
  v.stride = bv.byteStride ? bv.byteStride : v.element;
  const std::size_t need = v.count ? acc.byteOffset + v.stride * (v.count - 1) + v.element : 0;
  if (bv.byteOffset + bv.byteLength > buf.data.size() || need > bv.byteLength)
    throw std::runtime_error(what + " accessor " + std::to_string(index) + " reads past the end of its buffer");
  v.data = buf.data.data() + bv.byteOffset + acc.byteOffset;
  return v;
}

std::vector<float> read_floats(const tinygltf::Model& model, int index, int components, const std::string& what) {
  const AccessorView v = view_accessor(model, index, what);
  if (v.components != components)
    throw std::runtime_error(what + " accessor " + std::to_string(index) + " has " + std::to_string(v.components) +
                             " components, expected " + std::to_string(components));
  std::vector<float> out(v.count * std::size_t(components), 0.0f);
  if (!v.data) return out;
  const std::size_t csize = v.element / std::size_t(components);
  for (std::size_t i = 0; i < v.count; ++i)
    for (int c = 0; c < components; ++c)
      out[i * std::size_t(components) + std::size_t(c)] =
          component(v.data + i * v.stride + std::size_t(c) * csize, v.component_type, v.normalized);
  return out;
}

std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index) {
  const AccessorView v = view_accessor(model, index, "index");
  if (v.components != 1) throw std::runtime_error("index accessor " + std::to_string(index) + " is not scalar");
  std::vector<uint32_t> out(v.count, 0);
  if (!v.data) return out;
  for (std::size_t i = 0; i < v.count; ++i) {
    const unsigned char* p = v.data + i * v.stride;
    switch (v.component_type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out[i] = *p; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t x;
        std::memcpy(&x, p, 2);
        out[i] = x;
        break;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: std::memcpy(&out[i], p, 4); break;
      default:
        throw std::runtime_error("index accessor " + std::to_string(index) + " has component type " +
                                 std::to_string(v.component_type) + " (expected an unsigned integer)");
    }
  }
  return out;
}

int attribute(const tinygltf::Primitive& prim, const char* name) {
  const auto it = prim.attributes.find(name);
  return it == prim.attributes.end() ? -1 : it->second;
}

PrimitiveData decode_draco(const tinygltf::Model& model, const tinygltf::Value& ext) {
  if (!ext.IsObject() || !ext.Get("bufferView").IsNumber() || !ext.Get("attributes").IsObject())
    throw std::runtime_error("malformed KHR_draco_mesh_compression extension");
  const int bv_index = ext.Get("bufferView").GetNumberAsInt();
  if (bv_index < 0 || std::size_t(bv_index) >= model.bufferViews.size())
    throw std::runtime_error("KHR_draco_mesh_compression bufferView " + std::to_string(bv_index) + " out of range");
  const auto& bv = model.bufferViews[std::size_t(bv_index)];
  if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size() ||
      bv.byteOffset + bv.byteLength > model.buffers[std::size_t(bv.buffer)].data.size())
    throw std::runtime_error("KHR_draco_mesh_compression bufferView " + std::to_string(bv_index) +
                             " lies outside its buffer");
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(model.buffers[std::size_t(bv.buffer)].data.data() + bv.byteOffset),
              bv.byteLength);
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) throw std::runtime_error("Draco: " + decoded.status().error_msg_string());
  const std::unique_ptr<draco::Mesh> dm = std::move(decoded).value();

  PrimitiveData out;
  const std::size_t n = dm->num_points();
  const auto& attrs = ext.Get("attributes");
  auto read = [&](const char* name, int components, std::vector<float>& dst, bool required) {
    if (!attrs.Has(name)) {
      if (required) throw std::runtime_error(std::string("Draco primitive has no ") + name + " attribute");
      return;
    }
    const int id = attrs.Get(name).GetNumberAsInt();
    const draco::PointAttribute* a = id >= 0 ? dm->GetAttributeByUniqueId(uint32_t(id)) : nullptr;
    if (!a)
      throw std::runtime_error(std::string("Draco stream lacks attribute id ") + std::to_string(id) + " (" + name +
                               ")");
    if (a->num_components() < components)
      throw std::runtime_error(std::string("Draco attribute ") + name + " has too few components");
    dst.assign(n * std::size_t(components), 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
      const draco::AttributeValueIndex avi = a->mapped_index(draco::PointIndex(uint32_t(i)));
      if (!a->ConvertValue<float>(avi, int8_t(components), &dst[i * std::size_t(components)]))
        throw std::runtime_error(std::string("Draco attribute ") + name + " cannot be converted to float");
    }
  };
  read("POSITION", 3, out.positions, true);
  read("NORMAL", 3, out.normals, false);
  read("TEXCOORD_0", 2, out.uvs, false);
  out.indices.reserve(std::size_t(dm->num_faces()) * 3);
  for (draco::FaceIndex f(0); f < dm->num_faces(); ++f) {
    const auto& face = dm->face(f);
    for (int k = 0; k < 3; ++k) out.indices.push_back(face[k].value());
  }
  return out;
}

PrimitiveData read_primitive(const tinygltf::Model& model, const tinygltf::Primitive& prim) {
  if (const auto it = prim.extensions.find("KHR_draco_mesh_compression"); it != prim.extensions.end())
    return decode_draco(model, it->second);
  PrimitiveData out;
  const int pos = attribute(prim, "POSITION");
  if (pos < 0) throw std::runtime_error("primitive has no POSITION attribute");
  out.positions = read_floats(model, pos, 3, "POSITION");
  const std::size_t n = out.positions.size() / 3;
  if (const int nrm = attribute(prim, "NORMAL"); nrm >= 0) {
    out.normals = read_floats(model, nrm, 3, "NORMAL");
    if (out.normals.size() != 3 * n) throw std::runtime_error("NORMAL and POSITION counts differ");
  }
  if (const int uv = attribute(prim, "TEXCOORD_0"); uv >= 0) {
    out.uvs = read_floats(model, uv, 2, "TEXCOORD_0");
    if (out.uvs.size() != 2 * n) throw std::runtime_error("TEXCOORD_0 and POSITION counts differ");
  }
  if (prim.indices >= 0) out.indices = read_indices(model, prim.indices);
  return out;
}

Eigen::Matrix4d node_local(const tinygltf::Node& node) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (node.matrix.size() == 16) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m(r, c) = node.matrix[std::size_t(4 * c + r)];  // column-major
    return m;
  }
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  if (node.translation.size() == 3)
    t.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4)  // glTF stores (x, y, z, w)
    t.rotate(Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]).normalized());
  if (node.scale.size() == 3) t.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
  return t.matrix();
}

class GltfAssembler {
 public:
  GltfAssembler(const tinygltf::Model& model, MeshLoadReport& report) : model_(model), report_(report) {}

  void add_node(int index, const Eigen::Matrix4d& parent, int depth) {
    if (index < 0 || std::size_t(index) >= model_.nodes.size())
      throw std::runtime_error("node " + std::to_string(index) + " out of range");
    if (depth > int(model_.nodes.size())) throw std::runtime_error("node hierarchy has a cycle");
    const auto& node = model_.nodes[std::size_t(index)];
    const Eigen::Matrix4d world = parent * node_local(node);
    if (node.mesh >= 0) add_mesh(node.mesh, world);
    for (int child : node.children) add_node(child, world, depth + 1);
  }

  void add_mesh(int index, const Eigen::Matrix4d& world) {
    if (std::size_t(index) >= model_.meshes.size())
      throw std::runtime_error("mesh " + std::to_string(index) + " out of range");
    const Eigen::Matrix3d linear = world.topLeftCorner<3, 3>();
    const Eigen::Matrix3d normal_matrix = linear.inverse().transpose();
    const bool flip = linear.determinant() < 0;
    const auto& gm = model_.meshes[std::size_t(index)];
    for (std::size_t p = 0; p < gm.primitives.size(); ++p) {
      const auto& prim = gm.primitives[p];
      const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        continue;  // points and lines have no surface
      const std::string where = "mesh " + std::to_string(index) + " primitive " + std::to_string(p) + ": ";
      PrimitiveData d;
      try {
        d = read_primitive(model_, prim);
      } catch (const std::exception& e) {
        throw std::runtime_error(where + e.what());
      }
      if (prim.extensions.count("KHR_draco_mesh_compression")) report_.draco = true;
      const std::size_t n = d.positions.size() / 3;
      const auto base = uint32_t(mesh_.positions.size());
      for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector4d q(d.positions[3 * i], d.positions[3 * i + 1], d.positions[3 * i + 2], 1.0);
        mesh_.positions.push_back((world * q).head<3>().cast<float>());
        if (!d.normals.empty()) {
          const Eigen::Vector3d v(d.normals[3 * i], d.normals[3 * i + 1], d.normals[3 * i + 2]);
          mesh_.normals.push_back((normal_matrix * v).cast<float>());
          has_normal_.push_back(true);
        } else {
          mesh_.normals.push_back(Eigen::Vector3f::Zero());
          has_normal_.push_back(false);
        }
        mesh_.uvs.push_back(d.uvs.empty() ? Eigen::Vector2f::Zero() : Eigen::Vector2f(d.uvs[2 * i], d.uvs[2 * i + 1]));
      }
      if (d.uvs.empty() && n) all_uv_ = false;

      std::vector<uint32_t>& ix = d.indices;
      if (ix.empty()) {
        ix.resize(n);
        for (std::size_t i = 0; i < n; ++i) ix[i] = uint32_t(i);
      }
      for (std::size_t i = 0; i < ix.size(); ++i)
        if (ix[i] >= n)
          throw std::runtime_error(where + "index " + std::to_string(ix[i]) + " out of range (" + std::to_string(n) +
                                   " vertices)");
      auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
        if (flip) std::swap(b, c);
        mesh_.triangles.push_back({base + a, base + b, base + c});
      };
      if (mode == TINYGLTF_MODE_TRIANGLES) {
        for (std::size_t i = 0; i + 2 < ix.size(); i += 3) emit(ix[i], ix[i + 1], ix[i + 2]);
      } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (std::size_t i = 0; i + 2 < ix.size(); ++i)
          i % 2 ? emit(ix[i + 1], ix[i], ix[i + 2]) : emit(ix[i], ix[i + 1], ix[i + 2]);
      } else {
        for (std::size_t i = 1; i + 1 < ix.size(); ++i) emit(ix[0], ix[i], ix[i + 1]);
      }
    }
  }

  Mesh finish() {
    if (!all_uv_) mesh_.uvs.clear();
    finalize_mesh(mesh_, has_normal_, report_);
    return std::move(mesh_);
  }

 private:
  const tinygltf::Model& model_;
  MeshLoadReport& report_;
  Mesh mesh_;
  std::vector<bool> has_normal_;
  bool all_uv_ = true;
};

Mesh load_gltf(const std::string& path, bool binary, MeshLoadReport& report) {
  const tinygltf::Model model = parse_gltf(path, binary);
  GltfAssembler assembler(model, report);
  const Eigen::Matrix4d identity = Eigen::Matrix4d::Identity();
  if (!model.scenes.empty()) {
    const int s = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (std::size_t(s) >= model.scenes.size())
      throw std::runtime_error("default scene " + std::to_string(s) + " out of range");
    for (int node : model.scenes[std::size_t(s)].nodes) assembler.add_node(node, identity, 0);
  } else if (!model.nodes.empty()) {
    // No scene: every root node (one that is nobody's child).
    std::unordered_set<int> children;
    for (const auto& node : model.nodes) children.insert(node.children.begin(), node.children.end());
    for (std::size_t i = 0; i < model.nodes.size(); ++i)
      if (!children.count(int(i))) assembler.add_node(int(i), identity, 0);
  } else {
    for (std::size_t i = 0; i < model.meshes.size(); ++i) assembler.add_mesh(int(i), identity);
  }
  return assembler.finish();
}

}  // namespace

Mesh load_mesh(const std::string& path, MeshLoadReport* report) {
  MeshLoadReport local;
  MeshLoadReport& rep = report ? *report : local;
  rep = MeshLoadReport{};
  const std::string ext = lower_extension(path);
  require_regular_file(path);
  return with_file(path, [&] {
    if (ext == ".obj") {
      rep.format = "obj";
      return load_obj(path, rep);
    }
    if (ext == ".gltf" || ext == ".glb") {
      rep.format = ext.substr(1);
      return load_gltf(path, ext == ".glb", rep);
    }
    throw std::runtime_error("unsupported mesh format '" + ext + "' (expected .obj, .gltf or .glb)");
  });
}

}  // namespace rsibr
