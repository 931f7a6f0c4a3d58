// ParaView export written by hand (engine/ does not link VTK): VTK XML ImageData (.vti) per frame
// and a .pvd collection. Arrays are inline base64 "binary": one base64 run of a UInt32 byte count
// followed by the little-endian values (VTK's layout for uncompressed inline data).
#include "engine/io/atomic_file.hpp"
#include "engine/io/field_store.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <stdexcept>

namespace furrow {

namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the .vti writer copies little-endian bytes");

std::string num(double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest text that reads back exactly
  return std::string(buf, r.ptr);
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  return out;
}

void append_base64(std::string& out, const unsigned char* data, size_t n) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    const uint32_t t = uint32_t(data[i]) << 16 | uint32_t(data[i + 1]) << 8 | data[i + 2];
    out += kAlphabet[t >> 18];
    out += kAlphabet[(t >> 12) & 63];
    out += kAlphabet[(t >> 6) & 63];
    out += kAlphabet[t & 63];
  }
  if (i < n) {
    const uint32_t t = uint32_t(data[i]) << 16 | (i + 1 < n ? uint32_t(data[i + 1]) << 8 : 0u);
    out += kAlphabet[t >> 18];
    out += kAlphabet[(t >> 12) & 63];
    out += i + 1 < n ? kAlphabet[(t >> 6) & 63] : '=';
    out += '=';
  }
}

// <DataArray> of `bytes` (values of `type`, `components` per cell) as one base64 run.
void append_array(std::string& xml, const std::string& name, const char* type, int components,
                  const std::vector<unsigned char>& bytes) {
  if (bytes.size() > UINT32_MAX) throw std::invalid_argument("write_vti: array '" + name + "' exceeds 4 GB");
  std::vector<unsigned char> block(sizeof(uint32_t) + bytes.size());
  const uint32_t nbytes = uint32_t(bytes.size());
  std::memcpy(block.data(), &nbytes, sizeof nbytes);
  if (!bytes.empty()) std::memcpy(block.data() + sizeof nbytes, bytes.data(), bytes.size());
  xml += "        <DataArray type=\"" + std::string(type) + "\" Name=\"" + xml_escape(name) +
         "\" NumberOfComponents=\"" + std::to_string(components) + "\" format=\"binary\">";
  append_base64(xml, block.data(), block.size());
  xml += "</DataArray>\n";
}

std::vector<unsigned char> float_bytes(const std::vector<float>& v) {
  std::vector<unsigned char> b(v.size() * sizeof(float));
  if (!v.empty()) std::memcpy(b.data(), v.data(), b.size());
  return b;
}

}  // namespace

void write_vti(const std::string& path, const FieldFrame& f) {
  const size_t n = size_t(std::max(f.nx, 0)) * size_t(std::max(f.ny, 0));
  if (f.nx <= 0 || f.ny <= 0 || !(f.dx_m > 0.0) || f.active.size() != n)
    throw std::invalid_argument("write_vti: " + path + ": frame needs nx, ny > 0, dx_m > 0 and an nx*ny active mask");

  // VTK extents count points: nx x ny cells in the z = 0 plane, cell (i, j) = index i + nx j
  const std::string extent = "0 " + std::to_string(f.nx) + " 0 " + std::to_string(f.ny) + " 0 0";
  std::string first_scalar;
  for (const auto& info : field_registry())
    if (!info.vector && f.scalars.count(info.name) && first_scalar.empty()) first_scalar = info.name;

  std::string xml;
  xml.reserve(n * 40 + 1024);
  xml += "<?xml version=\"1.0\"?>\n";
  xml += "<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n";
  xml += "  <ImageData WholeExtent=\"" + extent + "\" Origin=\"" + num(f.origin_m.x()) + " " +
         num(f.origin_m.y()) + " 0\" Spacing=\"" + num(f.dx_m) + " " + num(f.dx_m) + " " + num(f.dx_m) + "\">\n";
  xml += "    <FieldData>\n      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">" +
         num(f.time_s) + "</DataArray>\n    </FieldData>\n";
  xml += "    <Piece Extent=\"" + extent + "\">\n      <CellData";
  if (!first_scalar.empty()) xml += " Scalars=\"" + first_scalar + "\"";
  if (!f.velocity_x.empty()) xml += " Vectors=\"velocity\"";
  xml += ">\n";
  for (const auto& info : field_registry()) {
    if (info.vector) {
      if (f.velocity_x.empty()) continue;
      if (f.velocity_x.size() != n || f.velocity_y.size() != n)
        throw std::invalid_argument("write_vti: " + path + ": velocity must have nx*ny cells");
      std::vector<float> v(3 * n, 0.0f);
      for (size_t c = 0; c < n; ++c) {
        v[3 * c] = f.velocity_x[c];
        v[3 * c + 1] = f.velocity_y[c];
      }
      append_array(xml, info.name, "Float32", 3, float_bytes(v));
    } else if (auto it = f.scalars.find(info.name); it != f.scalars.end()) {
      if (it->second.size() != n)
        throw std::invalid_argument("write_vti: " + path + ": field '" + info.name + "' must have nx*ny cells");
      append_array(xml, info.name, "Float32", 1, float_bytes(it->second));
    }
  }
  // ParaView hides cells flagged HIDDENCELL (32) in vtkGhostType: cells without material
  std::vector<unsigned char> ghost(n);
  for (size_t c = 0; c < n; ++c) ghost[c] = f.active[c] ? 0 : 32;
  append_array(xml, "vtkGhostType", "UInt8", 1, ghost);
  xml += "      </CellData>\n    </Piece>\n  </ImageData>\n</VTKFile>\n";
  write_file_atomic(path, xml);
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
  std::string xml = "<?xml version=\"1.0\"?>\n";
  xml += "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
  for (const auto& e : entries)
    xml += "    <DataSet timestep=\"" + num(e.time_s) + "\" group=\"\" part=\"0\" file=\"" +
           xml_escape(e.file) + "\"/>\n";
  xml += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(path, xml);
}

}  // namespace furrow
