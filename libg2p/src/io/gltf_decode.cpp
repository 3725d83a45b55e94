// Compressed, quantized, sparse and instanced glTF made plain (gltf_decode.h),
// as the glTF 2.0 specification (§3.6 buffers and accessors, §3.6.2.3 sparse
// accessors, §3.11 the GLB container) and the extensions' own specifications
// define the data: KHR_draco_mesh_compression, EXT_meshopt_compression,
// KHR_mesh_quantization, EXT_mesh_gpu_instancing, EXT_texture_webp and
// KHR_texture_basisu.
#include "gltf_decode.h"

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string_view>

namespace g2p::detail {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kMeshopt = "EXT_meshopt_compression";
constexpr const char* kQuantization = "KHR_mesh_quantization";
constexpr const char* kInstancing = "EXT_mesh_gpu_instancing";
constexpr const char* kWebp = "EXT_texture_webp";
constexpr const char* kBasisu = "KHR_texture_basisu";

// glTF's componentType codes.
enum Component : int {
  kByte = 5120,
  kUnsignedByte = 5121,
  kShort = 5122,
  kUnsignedShort = 5123,
  kUnsignedInt = 5125,
  kFloat = 5126,
};

std::uint32_t read_u32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);  // GLB is little-endian, as is every platform libg2p builds on
  return v;
}

void append_u32(std::string& out, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}

// The JSON and the binary chunk of a .glb, or the whole .gltf as JSON.
struct Container {  // views of the file's bytes
  std::string_view json_text;
  std::string_view bin;
  bool glb = false;
};

Result<Container> split_container(const std::string& bytes) {
  Container c;
  if (bytes.size() < 4 || bytes.compare(0, 4, "glTF") != 0) {
    c.json_text = bytes;
    return c;
  }
  c.glb = true;
  if (bytes.size() < 20) return Status::ParseError("GLB header truncated");
  const std::uint64_t length = std::min<std::uint64_t>(read_u32(bytes, 8), bytes.size());
  std::uint64_t at = 12;
  for (int chunk = 0; at + 8 <= length; ++chunk) {
    const std::uint64_t size = read_u32(bytes, at), type = read_u32(bytes, at + 4);
    if (at + 8 + size > length) return Status::ParseError("GLB chunk " + std::to_string(chunk) + " truncated");
    if (chunk == 0 && type != 0x4E4F534Au) return Status::ParseError("GLB first chunk is not JSON");
    if (chunk == 0) c.json_text = std::string_view(bytes).substr(at + 8, size);
    if (chunk == 1 && type == 0x004E4942u) c.bin = std::string_view(bytes).substr(at + 8, size);
    at += 8 + size;
  }
  return c;
}

const json* extension(const json& obj, const char* name) {
  if (!obj.is_object()) return nullptr;
  auto e = obj.find("extensions");
  if (e == obj.end() || !e->is_object()) return nullptr;
  auto x = e->find(name);
  return x != e->end() && x->is_object() ? &*x : nullptr;
}

void erase_extension(json& obj, const char* name) {
  auto e = obj.find("extensions");
  if (e == obj.end() || !e->is_object()) return;
  e->erase(name);
  if (e->empty()) obj.erase("extensions");
}

const json& array_of(const json& doc, const char* key) {
  static const json kEmpty = json::array();
  auto it = doc.find(key);
  return it != doc.end() && it->is_array() ? *it : kEmpty;
}

// A non-negative integer member, or `fallback` when absent; -1 when present but not one.
long long index_or(const json& obj, const char* key, long long fallback) {
  auto it = obj.find(key);
  if (it == obj.end()) return fallback;
  return it->is_number_unsigned() || (it->is_number_integer() && it->get<long long>() >= 0) ? it->get<long long>() : -1;
}

int components_of(const std::string& type) {
  static const std::map<std::string, int> kCounts = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                                     {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  auto it = kCounts.find(type);
  return it == kCounts.end() ? 0 : it->second;
}

int component_size(long long type) {
  switch (type) {
    case kByte:
    case kUnsignedByte: return 1;
    case kShort:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0;
  }
}

// One component as a float: normalized integers as §3.11's table says.
float component_value(const char* p, long long type, bool normalized) {
  switch (type) {
    case kByte: {
      std::int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.f, -1.f) : static_cast<float>(v);
    }
    case kUnsignedByte: {
      std::uint8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? v / 255.f : static_cast<float>(v);
    }
    case kShort: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.f, -1.f) : static_cast<float>(v);
    }
    case kUnsignedShort: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.f : static_cast<float>(v);
    }
    case kUnsignedInt: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return static_cast<float>(v);
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

std::uint32_t index_value(const char* p, long long type) {
  if (type == kUnsignedByte) return static_cast<std::uint8_t>(*p);
  if (type == kUnsignedShort) {
    std::uint16_t v;
    std::memcpy(&v, p, 2);
    return v;
  }
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// Base64 (RFC 4648) of a data: URI's payload.
Result<std::string> base64_decode(const std::string& text, std::size_t from) {
  std::array<int, 256> value;
  value.fill(-1);
  const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (int i = 0; i < 64; ++i) value[static_cast<unsigned char>(alphabet[i])] = i;
  std::string out;
  out.reserve((text.size() - from) / 4 * 3);
  unsigned bits = 0;
  int count = 0;
  for (std::size_t i = from; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '=') break;
    if (value[c] < 0) return Status::ParseError("invalid base64 in a data URI");
    bits = (bits << 6) | static_cast<unsigned>(value[c]);
    if ((count += 6) >= 8) {
      count -= 8;
      out.push_back(static_cast<char>((bits >> count) & 0xFF));
    }
  }
  return out;
}

std::string percent_decode(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

// The rewrite in progress: the document, every buffer view's bytes (decoded),
// and where new views and accessors go.
class Rewriter {
 public:
  Rewriter(json doc, std::string base_dir) : doc_(std::move(doc)), base_dir_(std::move(base_dir)) {}

  Status run(const Container& c, DecodedGltf& out);

 private:
  Status read_buffers(const Container& c);
  Status decode_views();
  Status decode_draco();
  Status dequantize_attributes();
  Status expand_instances();
  void choose_images();
  std::string write_glb() const;

  Result<std::vector<float>> read_floats(long long accessor, int& components) const;
  Result<std::vector<std::uint32_t>> read_indices(long long accessor) const;
  long long add_view(std::string bytes, long long stride = 0);
  long long add_float_accessor(const std::vector<float>& values, int components, const json& like, bool bounds);
  long long add_index_accessor(const std::vector<std::uint32_t>& indices);

  json doc_;
  std::string base_dir_;
  // Buffers are views of the file's bytes (a GLB's binary chunk) or owned
  // (data URIs, external files); buffer views are slices of them or owned
  // (decoded). Nothing of the file is copied until the GLB is written.
  std::deque<std::string> owned_;
  std::vector<std::string_view> buffers_;
  std::vector<bool> fallback_;  // EXT_meshopt_compression fallback buffers (no data of their own)
  std::vector<std::string_view> views_;
  std::vector<std::string> notes_;
  std::set<std::string> handled_;
};

Status Rewriter::read_buffers(const Container& c) {
  const json& buffers = array_of(doc_, "buffers");
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    const json& b = buffers[i];
    const std::string where = "buffer " + std::to_string(i);
    const long long length = b.is_object() ? index_or(b, "byteLength", -1) : -1;
    if (length < 0) return Status::ParseError(where + ": no byteLength");
    const json* meshopt = extension(b, kMeshopt);
    auto uri = b.find("uri");
    std::string_view data;
    bool fallback = false;
    if (uri == b.end() || !uri->is_string()) {
      if (meshopt != nullptr && meshopt->value("fallback", false)) {
        fallback = true;
      } else if (c.glb && i == 0) {
        data = c.bin;
      } else {
        return Status::ParseError(where + ": no uri, and not the GLB's binary chunk");
      }
    } else {
      const std::string u = uri->get<std::string>();
      if (u.rfind("data:", 0) == 0) {
        const std::size_t comma = u.find(',');
        if (comma == std::string::npos || u.substr(0, comma).find(";base64") == std::string::npos)
          return Status::ParseError(where + ": a data URI that is not base64");
        Result<std::string> decoded = base64_decode(u, comma + 1);
        if (!decoded.ok()) return decoded.status().with_context(where);
        data = owned_.emplace_back(std::move(*decoded));
      } else {
        if (base_dir_.empty())
          return Status::Unsupported(where + ": its data is in the file '" + u +
                                     "', which a model read from memory cannot reach");
        const fs::path path = fs::path(base_dir_) / percent_decode(u);
        std::ifstream in(path, std::ios::binary);
        if (!in) return Status::NotFound(where + ": cannot open '" + path.string() + "'");
        std::ostringstream s;
        s << in.rdbuf();
        data = owned_.emplace_back(s.str());
      }
    }
    if (!fallback && static_cast<long long>(data.size()) < length)
      return Status::ParseError(where + ": " + std::to_string(data.size()) + " bytes where byteLength says " +
                                std::to_string(length));
    if (!fallback) data = data.substr(0, static_cast<std::size_t>(length));
    buffers_.push_back(data);
    fallback_.push_back(fallback);
  }
  return Status::Ok();
}

// Every buffer view's bytes: a slice of its buffer, or EXT_meshopt_compression's
// stream decoded (the extension's specification: mode ATTRIBUTES, TRIANGLES or
// INDICES, then filter NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL).
Status Rewriter::decode_views() {
  const json& views = array_of(doc_, "bufferViews");
  for (std::size_t i = 0; i < views.size(); ++i) {
    const json& v = views[i];
    const std::string where = "bufferView " + std::to_string(i);
    if (!v.is_object()) return Status::ParseError(where + ": not an object");
    const json* meshopt = extension(v, kMeshopt);
    const json& source = meshopt != nullptr ? *meshopt : v;
    const long long buffer = index_or(source, "buffer", -1), offset = index_or(source, "byteOffset", 0),
                    length = index_or(source, "byteLength", -1);
    if (buffer < 0 || buffer >= static_cast<long long>(buffers_.size()))
      return Status::ParseError(where + ": buffer " + std::to_string(buffer) + " does not exist");
    if (length < 0 || offset < 0) return Status::ParseError(where + ": no valid byteOffset and byteLength");
    const std::string_view data = buffers_[static_cast<std::size_t>(buffer)];
    if (fallback_[static_cast<std::size_t>(buffer)] && meshopt == nullptr)
      return Status::ParseError(where + ": reads buffer " + std::to_string(buffer) + ", a " + kMeshopt +
                                " fallback with no data, without the extension");
    if (static_cast<unsigned long long>(offset) + static_cast<unsigned long long>(length) > data.size())
      return Status::ParseError(where + ": bytes " + std::to_string(offset) + "+" + std::to_string(length) +
                                " past the end of buffer " + std::to_string(buffer) + " (" +
                                std::to_string(data.size()) + " bytes)");
    const unsigned char* src = reinterpret_cast<const unsigned char*>(data.data()) + offset;
    if (meshopt == nullptr) {
      views_.push_back(data.substr(static_cast<std::size_t>(offset), static_cast<std::size_t>(length)));
      continue;
    }
    handled_.insert(kMeshopt);
    const long long count = index_or(*meshopt, "count", -1), stride = index_or(*meshopt, "byteStride", -1);
    const std::string mode = meshopt->value("mode", std::string()), filter = meshopt->value("filter", "NONE");
    const std::string bad = where + ": " + kMeshopt + " ";
    if (count < 0 || stride <= 0 || stride > 256) return Status::ParseError(bad + "needs a count and a byteStride");
    if (count > (1ll << 31) / stride) return Status::ParseError(bad + "count times byteStride exceeds 2 GiB");
    std::string out(static_cast<std::size_t>(count * stride), '\0');
    int rc = -1;
    if (mode == "ATTRIBUTES") {
      if (stride % 4 != 0) return Status::ParseError(bad + "ATTRIBUTES need a byteStride of a multiple of 4");
      rc = meshopt_decodeVertexBuffer(out.data(), static_cast<std::size_t>(count), static_cast<std::size_t>(stride),
                                      src, static_cast<std::size_t>(length));
    } else if (mode == "TRIANGLES" || mode == "INDICES") {
      if (stride != 2 && stride != 4) return Status::ParseError(bad + mode + " need a byteStride of 2 or 4");
      if (mode == "TRIANGLES" && count % 3 != 0) return Status::ParseError(bad + "TRIANGLES need a count of 3n");
      rc = mode == "TRIANGLES"
               ? meshopt_decodeIndexBuffer(out.data(), static_cast<std::size_t>(count),
                                           static_cast<std::size_t>(stride), src, static_cast<std::size_t>(length))
               : meshopt_decodeIndexSequence(out.data(), static_cast<std::size_t>(count),
                                             static_cast<std::size_t>(stride), src, static_cast<std::size_t>(length));
    } else {
      return Status::ParseError(bad + "mode '" + mode + "' is not ATTRIBUTES, TRIANGLES or INDICES");
    }
    if (rc != 0) return Status::ParseError(bad + "data do not decode (meshoptimizer error " + std::to_string(rc) + ")");
    if (filter == "OCTAHEDRAL") {
      if (stride != 4 && stride != 8) return Status::ParseError(bad + "OCTAHEDRAL needs a byteStride of 4 or 8");
      meshopt_decodeFilterOct(out.data(), static_cast<std::size_t>(count), static_cast<std::size_t>(stride));
    } else if (filter == "QUATERNION") {
      if (stride != 8) return Status::ParseError(bad + "QUATERNION needs a byteStride of 8");
      meshopt_decodeFilterQuat(out.data(), static_cast<std::size_t>(count), static_cast<std::size_t>(stride));
    } else if (filter == "EXPONENTIAL") {
      if (stride % 4 != 0) return Status::ParseError(bad + "EXPONENTIAL needs a byteStride of a multiple of 4");
      meshopt_decodeFilterExp(out.data(), static_cast<std::size_t>(count), static_cast<std::size_t>(stride));
    } else if (filter != "NONE") {
      return Status::ParseError(bad + "filter '" + filter + "' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
    }
    views_.push_back(owned_.emplace_back(std::move(out)));
  }
  return Status::Ok();
}

long long Rewriter::add_view(std::string bytes, long long stride) {
  json v = {{"buffer", 0}, {"byteLength", bytes.size()}};
  if (stride > 0) v["byteStride"] = stride;
  doc_["bufferViews"].push_back(std::move(v));
  views_.push_back(owned_.emplace_back(std::move(bytes)));
  return static_cast<long long>(views_.size()) - 1;
}

long long Rewriter::add_float_accessor(const std::vector<float>& values, int components, const json& like,
                                       bool bounds) {
  std::string bytes(values.size() * sizeof(float), '\0');
  std::memcpy(bytes.data(), values.data(), bytes.size());
  json a = {{"bufferView", add_view(std::move(bytes))},
            {"componentType", kFloat},
            {"count", values.size() / static_cast<std::size_t>(components)},
            {"type", like.value("type", std::string("SCALAR"))}};
  if (like.contains("name")) a["name"] = like["name"];
  if (bounds && !values.empty()) {
    std::vector<float> lo(values.begin(), values.begin() + components), hi = lo;
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::size_t k = i % static_cast<std::size_t>(components);
      lo[k] = std::min(lo[k], values[i]), hi[k] = std::max(hi[k], values[i]);
    }
    a["min"] = lo, a["max"] = hi;
  }
  doc_["accessors"].push_back(std::move(a));
  return static_cast<long long>(doc_["accessors"].size()) - 1;
}

long long Rewriter::add_index_accessor(const std::vector<std::uint32_t>& indices) {
  std::string bytes(indices.size() * 4, '\0');
  std::memcpy(bytes.data(), indices.data(), bytes.size());
  doc_["accessors"].push_back({{"bufferView", add_view(std::move(bytes))},
                               {"componentType", kUnsignedInt},
                               {"count", indices.size()},
                               {"type", "SCALAR"}});
  return static_cast<long long>(doc_["accessors"].size()) - 1;
}

// An accessor's elements as floats (normalized integers scaled, sparse
// substitutions applied, no bufferView: zeros), `components` per element.
Result<std::vector<float>> Rewriter::read_floats(long long index, int& components) const {
  const json& accessors = array_of(doc_, "accessors");
  const std::string where = "accessor " + std::to_string(index);
  if (index < 0 || index >= static_cast<long long>(accessors.size()))
    return Status::ParseError(where + " does not exist");
  const json& a = accessors[static_cast<std::size_t>(index)];
  const long long type = a.is_object() ? index_or(a, "componentType", -1) : -1, count = index_or(a, "count", -1);
  components = a.is_object() ? components_of(a.value("type", std::string())) : 0;
  const int size = component_size(type);
  if (size == 0 || components == 0 || count < 0) return Status::ParseError(where + ": no valid type or count");
  if (count > (1ll << 28)) return Status::ParseError(where + ": " + std::to_string(count) + " elements");
  const bool normalized = a.value("normalized", false);
  std::vector<float> out(static_cast<std::size_t>(count * components), 0.f);
  const auto read_into = [&](long long view_index, long long offset, long long stride, long long n,
                             const std::function<void(long long, const char*)>& put) -> Status {
    if (view_index < 0 || view_index >= static_cast<long long>(views_.size()))
      return Status::ParseError(where + ": bufferView " + std::to_string(view_index) + " does not exist");
    const std::string_view view = views_[static_cast<std::size_t>(view_index)];
    const long long element = static_cast<long long>(size) * components;
    if (stride == 0) stride = element;
    if (n > 0 && (offset < 0 || offset + (n - 1) * stride + element > static_cast<long long>(view.size())))
      return Status::ParseError(where + ": " + std::to_string(n) + " elements past the end of bufferView " +
                                std::to_string(view_index));
    for (long long e = 0; e < n; ++e) put(e, view.data() + offset + e * stride);
    return Status::Ok();
  };
  const auto put_element = [&](long long e, const char* p) {
    for (int k = 0; k < components; ++k)
      out[static_cast<std::size_t>(e * components + k)] = component_value(p + k * size, type, normalized);
  };
  if (a.contains("bufferView")) {
    const long long view = index_or(a, "bufferView", -1);
    const json& views = array_of(doc_, "bufferViews");
    const long long stride = view >= 0 && view < static_cast<long long>(views.size())
                                 ? index_or(views[static_cast<std::size_t>(view)], "byteStride", 0)
                                 : 0;
    G2P_RETURN_IF_ERROR(read_into(view, index_or(a, "byteOffset", 0), stride, count, put_element));
  }
  if (auto sparse = a.find("sparse"); sparse != a.end() && sparse->is_object()) {
    const long long n = index_or(*sparse, "count", -1);
    const json& idx = sparse->value("indices", json::object());
    const json& val = sparse->value("values", json::object());
    const long long idx_type = index_or(idx, "componentType", -1);
    if (n < 0 || n > count || (idx_type != kUnsignedByte && idx_type != kUnsignedShort && idx_type != kUnsignedInt))
      return Status::ParseError(where + ": sparse accessor without a valid count or index type");
    std::vector<std::uint32_t> at(static_cast<std::size_t>(n));
    const int isize = component_size(idx_type);
    const long long iview = index_or(idx, "bufferView", -1), ioffset = index_or(idx, "byteOffset", 0);
    if (iview < 0 || iview >= static_cast<long long>(views_.size()) ||
        ioffset + n * isize > static_cast<long long>(views_[static_cast<std::size_t>(iview)].size()))
      return Status::ParseError(where + ": sparse indices past the end of their bufferView");
    for (long long e = 0; e < n; ++e) {
      at[static_cast<std::size_t>(e)] =
          index_value(views_[static_cast<std::size_t>(iview)].data() + ioffset + e * isize, idx_type);
      if (at[static_cast<std::size_t>(e)] >= count)
        return Status::ParseError(where + ": sparse index " + std::to_string(at[static_cast<std::size_t>(e)]) +
                                  " out of range (" + std::to_string(count) + " elements)");
    }
    G2P_RETURN_IF_ERROR(
        read_into(index_or(val, "bufferView", -1), index_or(val, "byteOffset", 0), 0, n,
                  [&](long long e, const char* p) { put_element(at[static_cast<std::size_t>(e)], p); }));
  }
  return out;
}

Result<std::vector<std::uint32_t>> Rewriter::read_indices(long long index) const {
  int components = 0;
  Result<std::vector<float>> values = read_floats(index, components);
  if (!values.ok()) return values.status();
  std::vector<std::uint32_t> out(values->size());
  for (std::size_t i = 0; i < values->size(); ++i) out[i] = static_cast<std::uint32_t>((*values)[i]);
  return out;
}

// KHR_draco_mesh_compression: each compressed primitive's attributes and
// indices decoded by libdraco into new plain accessors.
Status Rewriter::decode_draco() {
  if (!doc_.contains("meshes") || !doc_["meshes"].is_array()) return Status::Ok();
  int decoded = 0;
  for (std::size_t m = 0; m < doc_["meshes"].size(); ++m) {
    json& mesh = doc_["meshes"][m];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (std::size_t p = 0; p < mesh["primitives"].size(); ++p) {
      json& prim = mesh["primitives"][p];
      const json* ext = extension(prim, kDraco);
      if (ext == nullptr) continue;
      const std::string where = "mesh " + std::to_string(m) + " primitive " + std::to_string(p) + ": " + kDraco;
      const long long view = index_or(*ext, "bufferView", -1);
      if (view < 0 || view >= static_cast<long long>(views_.size()))
        return Status::ParseError(where + ": bufferView " + std::to_string(view) + " does not exist");
      const std::string_view bytes = views_[static_cast<std::size_t>(view)];
      draco::DecoderBuffer buffer;
      buffer.Init(bytes.data(), bytes.size());
      draco::Decoder decoder;
      auto result = decoder.DecodeMeshFromBuffer(&buffer);
      if (!result.ok() || result.value() == nullptr)
        return Status::ParseError(where + ": the data do not decode (" +
                                  (result.ok() ? std::string("not a mesh") : result.status().error_msg_string()) + ")");
      const draco::Mesh& dm = *result.value();
      const std::size_t points = dm.num_points();
      const json attributes = ext->value("attributes", json::object());
      json& prim_attributes = prim["attributes"];
      for (auto it = attributes.begin(); it != attributes.end(); ++it) {
        const long long id = it->is_number_integer() ? it->get<long long>() : -1;
        const draco::PointAttribute* att =
            id >= 0 ? dm.GetAttributeByUniqueId(static_cast<std::uint32_t>(id)) : nullptr;
        if (att == nullptr)
          return Status::ParseError(where + ": no attribute " + std::to_string(id) + " for " + it.key());
        if (!prim_attributes.contains(it.key()) || !prim_attributes[it.key()].is_number_integer())
          return Status::ParseError(where + ": " + it.key() + " has no accessor");
        const long long old = prim_attributes[it.key()].get<long long>();
        const json& accessors = array_of(doc_, "accessors");
        if (old < 0 || old >= static_cast<long long>(accessors.size()))
          return Status::ParseError(where + ": " + it.key() + "'s accessor does not exist");
        const json like = accessors[static_cast<std::size_t>(old)];
        const int components = components_of(like.value("type", std::string()));
        if (components == 0 || components > 4)
          return Status::ParseError(where + ": " + it.key() + " has no valid type");
        // Integer data the accessor calls normalized, which Draco did not flag, scaled here.
        float scale = 1.f;
        if (like.value("normalized", false) && !att->normalized()) {
          switch (att->data_type()) {
            case draco::DT_UINT8: scale = 1.f / 255.f; break;
            case draco::DT_INT8: scale = 1.f / 127.f; break;
            case draco::DT_UINT16: scale = 1.f / 65535.f; break;
            case draco::DT_INT16: scale = 1.f / 32767.f; break;
            default: break;
          }
        }
        std::vector<float> values(points * static_cast<std::size_t>(components));
        for (std::size_t i = 0; i < points; ++i) {
          if (!att->ConvertValue<float>(att->mapped_index(draco::PointIndex(static_cast<std::uint32_t>(i))),
                                        static_cast<std::int8_t>(components), &values[i * components]))
            return Status::ParseError(where + ": " + it.key() + " does not convert to numbers");
        }
        if (scale != 1.f)
          for (float& v : values) v = std::max(v * scale, -1.f);
        prim_attributes[it.key()] = add_float_accessor(values, components, like, it.key() == "POSITION");
      }
      std::vector<std::uint32_t> indices(static_cast<std::size_t>(dm.num_faces()) * 3);
      for (draco::FaceIndex f(0); f < dm.num_faces(); ++f)
        for (int k = 0; k < 3; ++k) indices[f.value() * 3 + k] = dm.face(f)[k].value();
      prim["indices"] = add_index_accessor(indices);
      erase_extension(prim, kDraco);
      ++decoded;
    }
  }
  if (decoded > 0) {
    handled_.insert(kDraco);
    notes_.push_back(std::string(kDraco) + ": " + std::to_string(decoded) + " primitive" + (decoded == 1 ? "" : "s") +
                     " decoded");
  }
  return Status::Ok();
}

// Attributes stored as integers (KHR_mesh_quantization) or as sparse
// accessors, and sparse indices, rewritten as plain float (uint32) accessors,
// so assimp reads what the file means; the node transforms that dequantize
// positions stay as they are. Normals and tangents are renormalised.
Status Rewriter::dequantize_attributes() {
  if (!doc_.contains("meshes") || !doc_["meshes"].is_array()) return Status::Ok();
  std::map<long long, long long> done;  // old accessor -> new
  const auto needs = [&](long long a, bool indices) {
    const json& accessors = array_of(doc_, "accessors");
    if (a < 0 || a >= static_cast<long long>(accessors.size()) || !accessors[static_cast<std::size_t>(a)].is_object())
      return false;
    const json& acc = accessors[static_cast<std::size_t>(a)];
    if (acc.contains("sparse")) return true;
    return !indices && index_or(acc, "componentType", -1) != kFloat;
  };
  for (json& mesh : doc_["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (json& prim : mesh["primitives"]) {
      if (!prim.is_object()) continue;
      if (prim.contains("attributes") && prim["attributes"].is_object())
        for (auto it = prim["attributes"].begin(); it != prim["attributes"].end(); ++it) {
          if (!it->is_number_integer() || it.key().rfind("JOINTS_", 0) == 0) continue;
          const long long a = it->get<long long>();
          if (!needs(a, false)) continue;
          if (auto d = done.find(a); d != done.end()) {
            *it = d->second;
            continue;
          }
          int components = 0;
          Result<std::vector<float>> read = read_floats(a, components);
          if (!read.ok()) return read.status();
          std::vector<float>& values = *read;
          if ((it.key() == "NORMAL" || it.key() == "TANGENT") && components >= 3)
            for (std::size_t i = 0; i + 2 < values.size(); i += static_cast<std::size_t>(components)) {
              const float n =
                  std::sqrt(values[i] * values[i] + values[i + 1] * values[i + 1] + values[i + 2] * values[i + 2]);
              if (n > 0)
                for (int k = 0; k < 3; ++k) values[i + k] /= n;
            }
          const json like = doc_["accessors"][static_cast<std::size_t>(a)];
          if (index_or(like, "componentType", -1) != kFloat) handled_.insert(kQuantization);
          const long long fresh = add_float_accessor(values, components, like, it.key() == "POSITION");
          done[a] = fresh;
          *it = fresh;
        }
      if (auto idx = prim.find("indices");
          idx != prim.end() && idx->is_number_integer() && needs(idx->get<long long>(), true)) {
        Result<std::vector<std::uint32_t>> indices = read_indices(idx->get<long long>());
        if (!indices.ok()) return indices.status();
        *idx = add_index_accessor(*indices);
      }
    }
  }
  return Status::Ok();
}

// EXT_mesh_gpu_instancing: a node drawn N times becomes N child nodes, each
// with the mesh and its instance's translation, rotation and scale (applied
// before the node's own transform, as the extension says).
Status Rewriter::expand_instances() {
  if (!doc_.contains("nodes") || !doc_["nodes"].is_array()) return Status::Ok();
  const std::size_t original = doc_["nodes"].size();
  long long instances = 0;
  for (std::size_t n = 0; n < original; ++n) {
    const json* ext = extension(doc_["nodes"][n], kInstancing);
    if (ext == nullptr) continue;
    const std::string where = "node " + std::to_string(n) + ": " + kInstancing;
    const json attributes = ext->value("attributes", json::object());
    std::map<std::string, std::vector<float>> values;
    long long count = -1;
    for (const char* name : {"TRANSLATION", "ROTATION", "SCALE"}) {
      if (!attributes.contains(name)) continue;
      int components = 0;
      const long long a = attributes[name].is_number_integer() ? attributes[name].get<long long>() : -1;
      Result<std::vector<float>> read = read_floats(a, components);
      if (!read.ok()) return read.status().with_context(where);
      values[name] = std::move(*read);
      const int want = std::string(name) == "ROTATION" ? 4 : 3;
      if (components != want) return Status::ParseError(where + ": " + name + " is not a VEC" + std::to_string(want));
      const long long c = static_cast<long long>(values[name].size()) / want;
      if (count >= 0 && c != count) return Status::ParseError(where + ": its attributes' counts differ");
      count = c;
    }
    json node = doc_["nodes"][n];
    erase_extension(node, kInstancing);
    if (count < 0 || !node.contains("mesh")) {
      doc_["nodes"][n] = node;
      continue;
    }
    if (count > 1000000) return Status::ParseError(where + ": " + std::to_string(count) + " instances");
    const json mesh = node["mesh"];
    node.erase("mesh");
    if (!node.contains("children")) node["children"] = json::array();
    for (long long i = 0; i < count; ++i) {
      json child = {{"mesh", mesh}};
      if (values.count("TRANSLATION"))
        child["translation"] =
            std::vector<float>(values["TRANSLATION"].begin() + 3 * i, values["TRANSLATION"].begin() + 3 * i + 3);
      if (values.count("ROTATION"))
        child["rotation"] =
            std::vector<float>(values["ROTATION"].begin() + 4 * i, values["ROTATION"].begin() + 4 * i + 4);
      if (values.count("SCALE"))
        child["scale"] = std::vector<float>(values["SCALE"].begin() + 3 * i, values["SCALE"].begin() + 3 * i + 3);
      node["children"].push_back(doc_["nodes"].size());
      doc_["nodes"].push_back(std::move(child));
    }
    doc_["nodes"][n] = std::move(node);
    instances += count;
  }
  if (instances > 0) {
    handled_.insert(kInstancing);
    notes_.push_back(std::string(kInstancing) + ": " + std::to_string(instances) + " instances placed as nodes");
  }
  return Status::Ok();
}

// EXT_texture_webp: the WebP image in place of the fallback (libg2p decodes
// WebP). KHR_texture_basisu: the fallback where there is one; a texture with
// only its KTX2 image is dropped from the materials, with a note.
void Rewriter::choose_images() {
  if (!doc_.contains("textures") || !doc_["textures"].is_array()) return;
  std::set<long long> dropped;
  for (std::size_t t = 0; t < doc_["textures"].size(); ++t) {
    json& texture = doc_["textures"][t];
    if (const json* webp = extension(texture, kWebp)) {
      if (webp->contains("source")) texture["source"] = (*webp)["source"];
      erase_extension(texture, kWebp);
      handled_.insert(kWebp);
    }
    if (extension(texture, kBasisu) != nullptr) {
      erase_extension(texture, kBasisu);
      handled_.insert(kBasisu);
      if (!texture.contains("source")) {
        dropped.insert(static_cast<long long>(t));
      } else {
        notes_.push_back("texture " + std::to_string(t) + ": its KTX2 image (" + kBasisu +
                         ") left for its PNG or JPEG fallback");
      }
    }
  }
  if (dropped.empty()) return;
  // Every textureInfo that names a dropped texture goes, wherever it sits in a material.
  const std::function<void(json&)> strip = [&](json& obj) {
    if (obj.is_object()) {
      for (auto it = obj.begin(); it != obj.end();) {
        if (it->is_object() && it->contains("index") && (*it)["index"].is_number_integer() &&
            dropped.count((*it)["index"].get<long long>())) {
          it = obj.erase(it);
        } else {
          strip(*it);
          ++it;
        }
      }
    } else if (obj.is_array()) {
      for (json& e : obj) strip(e);
    }
  };
  if (doc_.contains("materials")) strip(doc_["materials"]);
  for (long long t : dropped)
    notes_.push_back("texture " + std::to_string(t) + " is a KTX2 image (" + kBasisu +
                     "), which no Debian package decodes: read without it, as --no-textures would");
}

std::string Rewriter::write_glb() const {
  std::string bin;
  std::size_t total = 0;
  for (const std::string_view v : views_) total += v.size() + 3;
  bin.reserve(total);
  json doc = doc_;
  for (std::size_t i = 0; i < views_.size(); ++i) {
    bin.resize((bin.size() + 3) & ~std::size_t{3}, '\0');
    json& v = doc["bufferViews"][i];
    v["buffer"] = 0, v["byteOffset"] = bin.size(), v["byteLength"] = views_[i].size();
    erase_extension(v, kMeshopt);
    bin += views_[i];
  }
  bin.resize((bin.size() + 3) & ~std::size_t{3}, '\0');
  doc["buffers"] = json::array({{{"byteLength", bin.size()}}});
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    if (!doc.contains(key) || !doc[key].is_array()) continue;
    json kept = json::array();
    for (const json& e : doc[key])
      if (!e.is_string() || !handled_.count(e.get<std::string>())) kept.push_back(e);
    if (kept.empty())
      doc.erase(key);
    else
      doc[key] = std::move(kept);
  }
  std::string text = doc.dump();
  text.resize((text.size() + 3) & ~std::size_t{3}, ' ');
  std::string glb = "glTF";
  glb.reserve(28 + text.size() + bin.size());
  append_u32(glb, 2);
  append_u32(glb, static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
  append_u32(glb, static_cast<std::uint32_t>(text.size()));
  append_u32(glb, 0x4E4F534Au);
  glb += text;
  append_u32(glb, static_cast<std::uint32_t>(bin.size()));
  append_u32(glb, 0x004E4942u);
  glb += bin;
  return glb;
}

Status Rewriter::run(const Container& c, DecodedGltf& out) {
  G2P_RETURN_IF_ERROR(read_buffers(c));
  G2P_RETURN_IF_ERROR(decode_views());
  G2P_RETURN_IF_ERROR(decode_draco());
  G2P_RETURN_IF_ERROR(dequantize_attributes());
  G2P_RETURN_IF_ERROR(expand_instances());
  choose_images();
  if (handled_.count(kMeshopt)) notes_.insert(notes_.begin(), std::string(kMeshopt) + ": buffer views decoded");
  if (handled_.count(kQuantization))
    notes_.push_back(std::string(kQuantization) + ": integer attributes read as floats");
  std::string glb = write_glb();
  if (glb.size() > std::numeric_limits<std::uint32_t>::max())
    return Status::Unsupported("the decoded file exceeds the 4 GiB a GLB can hold");
  out.glb = std::move(glb);
  out.notes = std::move(notes_);
  return Status::Ok();
}

}  // namespace

GltfPlan plan_gltf(const std::string& json_bytes) {
  GltfPlan plan;
  Result<Container> c = split_container(json_bytes);
  if (!c.ok()) return plan;
  const json doc = json::parse(c->json_text.begin(), c->json_text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return plan;
  std::set<std::string> used;
  for (const char* key : {"extensionsUsed", "extensionsRequired"})
    for (const json& e : array_of(doc, key))
      if (e.is_string()) used.insert(e.get<std::string>());
  for (const char* e : {kDraco, kMeshopt, kQuantization, kInstancing, kWebp, kBasisu})
    if (used.count(e)) plan.rewrite.push_back(e);
  for (const json& a : array_of(doc, "accessors"))
    if (a.is_object() && a.contains("sparse")) {
      plan.rewrite.push_back("sparse accessors");
      break;
    }
  const json& scenes = array_of(doc, "scenes");
  if (scenes.size() > 1) {
    const long long chosen = index_or(doc, "scene", 0);
    plan.notes.push_back("the file has " + std::to_string(scenes.size()) + " scenes: scene " +
                         std::to_string(chosen < 0 ? 0 : chosen) + " (the default) is read, the others are not");
  }
  if (!array_of(doc, "skins").empty())
    plan.notes.push_back("skinned meshes are read in their bind pose (" +
                         std::to_string(array_of(doc, "skins").size()) + " skins; no animation is applied)");
  for (const json& mesh : array_of(doc, "meshes")) {
    if (!mesh.is_object()) continue;
    bool targets = false;
    for (const json& p : array_of(mesh, "primitives")) targets = targets || (p.is_object() && p.contains("targets"));
    if (targets) {
      plan.notes.push_back("morph targets are left at rest: the base shape is read, without the targets' weights");
      break;
    }
  }
  return plan;
}

Result<DecodedGltf> decode_gltf(const std::string& bytes, const std::string& base_dir) {
  Result<Container> split = split_container(bytes);
  if (!split.ok()) return split.status();
  const Container& c = *split;
  json doc = json::parse(c.json_text.begin(), c.json_text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return Status::ParseError("glTF JSON is not a valid object");
  DecodedGltf out;
  try {
    Rewriter rewriter(std::move(doc), base_dir);
    G2P_RETURN_IF_ERROR(rewriter.run(c, out));
  } catch (const json::exception& e) {
    return Status::ParseError(std::string("glTF JSON of an unexpected shape: ") + e.what());
  }
  return out;
}

}  // namespace g2p::detail
