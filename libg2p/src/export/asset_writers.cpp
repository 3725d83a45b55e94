// make_asset, MJCF and SDF texts, and write_asset.
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/file_util.h"
#include "core/json_text.h"
#include "export/asset_names.h"
#include "g2p/export.h"
#include "g2p/io.h"

namespace g2p {
namespace {

// Letters, digits and underscores only: safe in file names and XML names.
std::string safe_name(const std::string& s) {
  std::string out;
  for (unsigned char c : s) out += std::isalnum(c) ? static_cast<char>(c) : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "m_" + out;
  return out;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

std::string vec3(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else if (c == '-' && !out.empty() && out.back() == '-')
      out += ' ';  // never "--" inside comments
    else
      out += c;
  }
  return out;
}

// The mesh with exactly coincident vertices merged: the input's vertices
// split at UV and normal seams, which the exported visual meshes (positions
// and triangles only) do not need.
Mesh welded(const Mesh& mesh) {
  Mesh out;
  std::map<std::array<float, 3>, int> index;
  std::vector<int> remap(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector3f& p = mesh.positions[v];
    auto [it, added] = index.emplace(std::array<float, 3>{p.x(), p.y(), p.z()}, out.num_vertices());
    if (added) out.positions.push_back(p);
    remap[v] = it->second;
  }
  out.triangles.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles)
    out.triangles.emplace_back(remap[static_cast<std::size_t>(t[0])], remap[static_cast<std::size_t>(t[1])],
                               remap[static_cast<std::size_t>(t[2])]);
  return out;
}

}  // namespace

Result<SimulationAsset> make_asset(const std::string& name, const Mesh& object, const std::vector<Part>& parts,
                                   const Completion& completion, const PropertiesReport& report,
                                   const MaterialTable& table, const std::vector<ConvexDecomposition>& collision) {
  if (parts.size() != completion.parts.size() || parts.size() != report.parts.size())
    return Status::InvalidArgument("make_asset: parts, completion and report disagree in length");
  if (!collision.empty() && collision.size() != parts.size())
    return Status::InvalidArgument("make_asset: " + std::to_string(collision.size()) + " decompositions for " +
                                   std::to_string(parts.size()) + " parts");
  std::vector<ConvexDecomposition> made;  // with the default backend when none was given
  if (collision.empty()) {
    Result<std::unique_ptr<Decomposer>> d = make_decomposer("voxel-cut");
    if (!d.ok()) return d.status();
    made = decompose_parts(completion, **d, DecomposeOptions{}, "voxel-cut", &object, &parts);
  }
  const std::vector<ConvexDecomposition>& hulls = collision.empty() ? made : collision;
  SimulationAsset a;
  a.name = safe_name(name);
  std::vector<MassProperties> masses;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const CompletedPart& c = completion.parts[i];
    const PartReport& r = report.parts[i];
    if (c.mesh.num_faces() == 0 || !(r.mass.mass_kg > 0)) {
      a.notes.push_back("part " + std::to_string(i) + " has no closed volume or mass and is not exported");
      continue;
    }
    AssetPart p;
    p.part = static_cast<int>(i);
    p.material = table.valid_label(parts[i].label) ? table[parts[i].label].name : "Unknown";
    p.name = "part_" + std::to_string(i) + "_" + safe_name(p.material);
    if (table.valid_label(parts[i].label))
      for (int k = 0; k < 3; ++k)
        p.rgba[static_cast<std::size_t>(k)] = table[parts[i].label].color[static_cast<std::size_t>(k)] / 255.0;
    p.closed = c.mesh;
    p.visual = part_patch(object, parts[i]);
    p.collision = hulls[i];
    if (p.collision.hulls.empty())
      a.notes.push_back(p.name + " has no collision shape (" +
                        (p.collision.notes.empty() ? std::string("no hull") : p.collision.notes.back()) +
                        "); it is exported for its mass and looks only");
    if (p.collision.fell_back) a.notes.push_back(p.name + " collides as its single convex hull (decomposition failed)");
    p.properties = r.properties;
    p.mass = r.mass;
    if (!c.ok) a.notes.push_back(p.name + " failed its completion checks; exported as it is");
    masses.push_back(p.mass);
    a.parts.push_back(std::move(p));
  }
  if (a.parts.empty()) return Status::InvalidArgument("make_asset: no part has a closed volume and a mass");
  a.total = combine(masses);
  return a;
}

PropertiesReport with_export_notes(const PropertiesReport& report, const SimulationAsset& asset) {
  PropertiesReport out = report;
  for (const std::string& n : asset.notes) out.notes.push_back("export: " + n);
  return out;
}

std::string asset_report_json(const PropertiesReport& report, const SimulationAsset& asset,
                              const MaterialTable& table) {
  using nlohmann::json;
  json doc = json::parse(report_json(with_export_notes(report, asset), table));
  for (const AssetPart& p : asset.parts) {
    if (p.part < 0 || p.part >= static_cast<int>(doc["parts"].size())) continue;
    const ConvexDecomposition& c = p.collision;
    json files = json::array(), vertices = json::array();
    for (std::size_t k = 0; k < c.hulls.size(); ++k) {
      files.push_back("meshes/" + detail::hull_name(p, k) + ".obj");
      vertices.push_back(c.hulls[k].num_vertices());
    }
    json collision = {
        {"backend", c.backend},
        {"hulls", c.hulls.size()},
        {"hull_vertices", vertices},
        {"files", files},
        {"hulls_volume_m3", c.hulls_volume_m3},
        {"closed_volume_m3", c.part_volume_m3},
        {"volume_ratio", c.part_volume_m3 > 0 ? json(c.hulls_volume_m3 / c.part_volume_m3) : json(nullptr)},
        {"mean_distance_m", c.mean_distance_m},
        {"max_distance_m", c.max_distance_m},
        {"uncovered_mean_m", c.uncovered_mean_m},
        {"uncovered_max_m", c.uncovered_max_m},
        {"hull_budget", c.hull_budget},
        {"coverage_tolerance_m", c.coverage_tolerance_m},
        {"seconds", c.seconds},
        {"fell_back", c.fell_back},
        {"notes", c.notes}};
    doc["parts"][static_cast<std::size_t>(p.part)]["geometry"] = {
        {"closed", {{"triangles", p.closed.num_faces()}, {"volume_m3", enclosed_volume(p.closed)}}},
        {"visual", {{"triangles", p.visual.num_faces()}, {"file", "meshes/" + p.name + "_visual.obj"}}},
        {"collision", collision}};
  }
  if (!asset.identification_json.empty()) {
    const json id = json::parse(asset.identification_json, nullptr, /*allow_exceptions=*/false);
    if (!id.is_discarded()) doc["identification"] = id;
  }
  return detail::json_text(doc, 2) + "\n";
}

Status write_asset_report(const std::string& path, const PropertiesReport& report, const SimulationAsset& asset,
                          const MaterialTable& table) {
  return write_text_file(path, asset_report_json(report, asset, table));
}

std::string mjcf_text(const SimulationAsset& a, const ExportOptions& options) {
  std::ostringstream x;
  const MassProperties& m = a.total;
  x << "<mujoco model=\"" << a.name << "\">\n"
    << "  <!-- Written by libg2p (Gen2Physics). Metres, kilograms, seconds; +Z up. The body's inertial is\n"
    << "       libg2p's exact mass properties of the completed parts; geoms carry no mass. Each part collides\n"
    << "       as a set of convex hulls (class g2p_collision, group 3) and is drawn with its own surface\n"
    << "       (class g2p_visual, group 2), which does not collide. -->\n";
  for (const std::string& n : a.notes) x << "  <!-- " << xml_escape(n) << " -->\n";
  const MujocoContacts contacts = mujoco_contacts(a, options);
  if (options.scale_contacts)
    x << "  <!-- Contacts scaled to the object (libg2p docs/formats.md#contacts-scaled-to-the-object): smallest side "
      << num(contacts.smallest_side_m) << " m, dropped from its height " << num(contacts.height_m) << " m at "
      << num(contacts.impact_speed_m_s) << " m/s: contact time constant " << num(contacts.timeconst_s)
      << " s, time step " << num(contacts.timestep_s) << " s. -->\n";
  x << "  <compiler angle=\"radian\" meshdir=\"meshes\" inertiafromgeom=\"false\"/>\n"
    << "  <option gravity=\"0 0 -9.81\""
    << (options.scale_contacts || options.timestep_s > 0 ? " timestep=\"" + num(contacts.timestep_s) + "\"" : "")
    << (contacts.elliptic_cone ? " cone=\"elliptic\" impratio=\"" + num(contacts.impratio) + "\"" : "") << "/>\n"
    << "  <default>\n"
    << "    <default class=\"g2p_collision\"><geom type=\"mesh\" group=\"3\" contype=\"1\" "
       "conaffinity=\"1\"/></default>\n"
    << "    <default class=\"g2p_visual\"><geom type=\"mesh\" group=\"2\" contype=\"0\" conaffinity=\"0\"/></default>\n"
    << "  </default>\n  <asset>\n";
  for (const AssetPart& p : a.parts) {
    for (std::size_t k = 0; k < p.collision.hulls.size(); ++k)
      x << "    <mesh name=\"" << detail::hull_name(p, k) << "\" file=\"" << detail::hull_name(p, k) << ".obj\"/>\n";
    x << "    <mesh name=\"" << p.name << "_visual\" file=\"" << p.name << "_visual.obj\"/>\n";
  }
  x << "  </asset>\n  <worldbody>\n    <body name=\"" << a.name << "\">\n";
  if (options.free_joint) x << "      <freejoint name=\"" << a.name << "_free\"/>\n";
  const Eigen::Matrix3d& I = m.inertia;
  x << "      <inertial pos=\"" << vec3(m.center_of_mass) << "\" mass=\"" << num(m.mass_kg) << "\" fullinertia=\""
    << num(I(0, 0)) << " " << num(I(1, 1)) << " " << num(I(2, 2)) << " " << num(I(0, 1)) << " " << num(I(0, 2)) << " "
    << num(I(1, 2)) << "\"/>\n";
  for (std::size_t i = 0; i < a.parts.size(); ++i) {
    const AssetPart& p = a.parts[i];
    const PartProperties& pp = p.properties;
    const PartContact& c = contacts.parts[i];
    std::string contact =
        "friction=\"" + num(c.friction[0]) + " " + num(c.friction[1]) + " " + num(c.friction[2]) + "\"";
    if (c.condim != 3) contact += " condim=\"" + std::to_string(c.condim) + "\"";
    contact += " solref=\"" + num(c.solref[0]) + " " + num(c.solref[1]) + "\" solimp=\"" + num(c.solimp[0]) + " " +
               num(c.solimp[1]) + " " + num(c.solimp[2]) + " " + num(c.solimp[3]) + " " + num(c.solimp[4]) + "\"";
    if (c.solmix != 1.0) contact += " solmix=\"" + num(c.solmix) + "\"";
    const std::string rgba = num(p.rgba[0]) + " " + num(p.rgba[1]) + " " + num(p.rgba[2]) + " " + num(p.rgba[3]);
    x << "      <!-- " << p.name << ": " << to_string(pp.structure) << ", " << num(pp.density_kg_m3) << " kg/m^3, "
      << num(p.mass.mass_kg) << " kg, " << p.collision.hulls.size() << " convex hulls -->\n";
    for (std::size_t k = 0; k < p.collision.hulls.size(); ++k)
      x << "      <geom name=\"" << detail::hull_name(p, k) << "\" class=\"g2p_collision\" mesh=\""
        << detail::hull_name(p, k) << "\" rgba=\"" << rgba << "\" " << contact << "/>\n";
    x << "      <geom name=\"" << p.name << "_visual\" class=\"g2p_visual\" mesh=\"" << p.name << "_visual\" rgba=\""
      << rgba << "\"/>\n";
  }
  x << "    </body>\n  </worldbody>\n</mujoco>\n";
  return x.str();
}

std::string sdf_text(const SimulationAsset& a) {
  std::ostringstream x;
  const MassProperties& m = a.total;
  const Eigen::Matrix3d& I = m.inertia;
  x << "<?xml version=\"1.0\"?>\n<!-- Written by libg2p (Gen2Physics). Metres, kilograms; +Z up. -->\n"
    << "<sdf version=\"1.9\">\n  <model name=\"" << a.name << "\">\n    <link name=\"" << a.name << "\">\n"
    << "      <inertial>\n        <pose>" << vec3(m.center_of_mass) << " 0 0 0</pose>\n        <mass>" << num(m.mass_kg)
    << "</mass>\n        <inertia>\n          <ixx>" << num(I(0, 0)) << "</ixx>\n          <ixy>" << num(I(0, 1))
    << "</ixy>\n          <ixz>" << num(I(0, 2)) << "</ixz>\n          <iyy>" << num(I(1, 1))
    << "</iyy>\n          <iyz>" << num(I(1, 2)) << "</iyz>\n          <izz>" << num(I(2, 2))
    << "</izz>\n        </inertia>\n      </inertial>\n";
  for (const AssetPart& p : a.parts) {
    const PartProperties& pp = p.properties;
    for (std::size_t k = 0; k < p.collision.hulls.size(); ++k)
      x << "      <collision name=\"" << detail::hull_name(p, k) << "\">\n        <geometry><mesh><uri>meshes/"
        << detail::hull_name(p, k) << ".obj</uri></mesh></geometry>\n        <surface>\n          <friction><ode><mu>"
        << num(pp.friction_static) << "</mu><mu2>" << num(pp.friction_static)
        << "</mu2></ode></friction>\n          <bounce><restitution_coefficient>" << num(pp.restitution)
        << "</restitution_coefficient></bounce>\n        </surface>\n      </collision>\n";
    x << "      <visual name=\"" << p.name << "_visual\">\n        <geometry><mesh><uri>meshes/" << p.name
      << "_visual.obj</uri></mesh></geometry>\n        <material><diffuse>" << num(p.rgba[0]) << " " << num(p.rgba[1])
      << " " << num(p.rgba[2]) << " " << num(p.rgba[3]) << "</diffuse></material>\n      </visual>\n";
  }
  x << "    </link>\n  </model>\n</sdf>\n";
  return x.str();
}

Status write_asset(const std::string& dir, const SimulationAsset& a, const std::vector<std::string>& formats,
                   const ExportOptions& options) {
  if (!(options.contact_sink > 0 && options.contact_sink <= 0.5))
    return Status::InvalidArgument("write_asset: contact_sink must lie in (0, 0.5], got " + num(options.contact_sink));
  if (!(options.timestep_s >= 0 && options.timestep_s <= 0.1))
    return Status::InvalidArgument("write_asset: timestep_s must lie in [0, 0.1] s (0: from the contacts), got " +
                                   num(options.timestep_s));
  for (const std::string& f : formats)
    if (f != "mjcf" && f != "urdf" && f != "sdf")
      return Status::InvalidArgument("write_asset: unknown format '" + f + "' (mjcf, urdf, sdf)");
  std::string urdf;
  for (const std::string& f : formats)
    if (f == "urdf") {
      Result<std::string> u = urdf_text(a);
      if (!u.ok()) return u.status();
      urdf = *u;
    }
  G2P_RETURN_IF_ERROR(detail::ensure_directory(dir + "/meshes"));
  for (const AssetPart& p : a.parts) {
    for (std::size_t k = 0; k < p.collision.hulls.size(); ++k)
      G2P_RETURN_IF_ERROR(write_mesh(dir + "/meshes/" + detail::hull_name(p, k) + ".obj", p.collision.hulls[k]));
    G2P_RETURN_IF_ERROR(write_mesh(dir + "/meshes/" + p.name + "_visual.obj", welded(p.visual)));
    if (options.write_closed_volumes)
      G2P_RETURN_IF_ERROR(write_mesh(dir + "/meshes/" + p.name + "_closed.obj", p.closed));
  }
  for (const std::string& f : formats) {
    if (f == "mjcf") G2P_RETURN_IF_ERROR(write_text_file(dir + "/" + a.name + ".xml", mjcf_text(a, options)));
    if (f == "urdf") G2P_RETURN_IF_ERROR(write_text_file(dir + "/" + a.name + ".urdf", urdf));
    if (f == "sdf") G2P_RETURN_IF_ERROR(write_text_file(dir + "/" + a.name + ".sdf", sdf_text(a)));
  }
  return Status::Ok();
}

}  // namespace g2p
