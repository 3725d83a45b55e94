// check_in_mujoco: the exported MJCF as MuJoCo compiles and simulates it.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/file_util.h"
#include "export/mujoco_support.h"
#include "g2p/export.h"
#include "g2p/io.h"

namespace g2p {
namespace {

// Lowest height of any mesh vertex of the model's colliding geoms (not the
// visual meshes, which collide with nothing) in the current state.
double lowest_vertex(const mjModel* m, const mjData* d) {
  double lowest = std::numeric_limits<double>::infinity();
  detail::for_each_collision_vertex(m, d, [&](double, double, double z) { lowest = std::min(lowest, z); });
  return lowest;
}

}  // namespace

namespace detail {

Result<std::string> mjcf_with_absolute_meshdir(const std::string& mjcf_path) {
  namespace fs = std::filesystem;
  std::ifstream in(mjcf_path, std::ios::binary);
  if (!in) return Status::NotFound(mjcf_path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const fs::path source = fs::absolute(mjcf_path).parent_path();
  const std::string meshdir = "meshdir=\"meshes\"";
  const std::size_t at = xml.find(meshdir);
  if (at != std::string::npos) xml.replace(at, meshdir.size(), "meshdir=\"" + (source / "meshes").string() + "\"");
  return xml;
}

Result<mjModel*> load_mjcf_text(const std::string& xml, const std::string& what) {
  namespace fs = std::filesystem;
  std::string tmpl = (fs::temp_directory_path() / "g2p-mujoco-XXXXXX").string();
  if (mkdtemp(tmpl.data()) == nullptr) return Status::IoError(what + ": cannot create a temporary folder");
  const std::string path = tmpl + "/model.xml";
  Status s = write_text_file(path, xml);
  char error[1000] = "";
  mjModel* m = s.ok() ? mj_loadXML(path.c_str(), nullptr, error, sizeof error) : nullptr;
  std::error_code ec;
  fs::remove_all(tmpl, ec);
  if (!s.ok()) return s;
  if (m == nullptr) return Status::ParseError(what + ": MuJoCo: " + error);
  return m;
}

}  // namespace detail

bool have_mujoco() { return true; }

Result<EngineCheck> check_in_mujoco(const std::string& mjcf_path, double drop_height_m, double drop_seconds) {
  const detail::QuietMujocoWarnings quiet;
  Result<std::string> text = detail::mjcf_with_absolute_meshdir(mjcf_path);
  if (!text.ok()) return text.status();
  std::string xml = *text;

  EngineCheck out;
  out.engine = detail::engine_name();
  char error[1000] = "";
  {
    mjModel* m = mj_loadXML(mjcf_path.c_str(), nullptr, error, sizeof error);
    if (m == nullptr) return Status::ParseError(mjcf_path + ": MuJoCo: " + error);
    if (m->nbody < 2) {
      mj_deleteModel(m);
      return Status::InvalidArgument(mjcf_path + ": no body");
    }
    out.mass_kg = m->body_mass[1];
    out.center_of_mass = Eigen::Vector3d(m->body_ipos[3], m->body_ipos[4], m->body_ipos[5]);
    Eigen::Vector3d moments(m->body_inertia[3], m->body_inertia[4], m->body_inertia[5]);
    std::sort(moments.data(), moments.data() + 3);
    out.principal_moments = moments;
    mj_deleteModel(m);
  }
  if (drop_seconds <= 0 || xml.find("<freejoint") == std::string::npos) return out;

  // The same model over a plane, in a temporary copy that reads the meshes
  // from the original folder (nothing is written beside the user's files).
  mjModel* probe = mj_loadXML(mjcf_path.c_str(), nullptr, error, sizeof error);
  if (probe == nullptr) return Status::ParseError(mjcf_path + ": MuJoCo: " + error);
  mjData* pd = mj_makeData(probe);
  mj_forward(probe, pd);
  const double floor_z = lowest_vertex(probe, pd) - drop_height_m;
  mj_deleteData(pd);
  mj_deleteModel(probe);
  const std::string body = "  <worldbody>\n";
  const std::size_t wb = xml.find(body);
  if (wb == std::string::npos) return Status::ParseError(mjcf_path + ": no <worldbody> as libg2p writes it");
  char plane[200];
  std::snprintf(plane, sizeof plane, "    <geom name=\"g2p_floor\" type=\"plane\" size=\"0 0 1\" pos=\"0 0 %.9g\"/>\n",
                floor_z);
  xml.insert(wb + body.size(), plane);
  Result<mjModel*> loaded = detail::load_mjcf_text(xml, mjcf_path + " over a plane");
  if (!loaded.ok()) return loaded.status();
  mjModel* m = *loaded;
  mjData* d = mj_makeData(m);
  const int steps = static_cast<int>(std::ceil(drop_seconds / m->opt.timestep));
  out.dropped = true;
  out.finite = true;
  out.lowest_point_m = std::numeric_limits<double>::infinity();
  for (int i = 0; i < steps; ++i) {
    mj_step(m, d);
    // Every step: an impact lasts only a few when the time step is scaled to the object.
    const double low = lowest_vertex(m, d) - floor_z;
    if (!std::isfinite(low)) {
      out.finite = false;
      break;
    }
    out.lowest_point_m = std::min(out.lowest_point_m, low);
  }
  for (int i = 0; i < m->nv && out.finite; ++i) out.finite = std::isfinite(d->qvel[i]) && std::abs(d->qvel[i]) < 1e3;
  out.resting_lowest_m = lowest_vertex(m, d) - floor_z;
  out.final_speed_m_s = Eigen::Vector3d(d->qvel[0], d->qvel[1], d->qvel[2]).norm();
  out.final_height_m = d->xipos[3 + 2] - floor_z;
  const struct {
    int index;
    const char* what;
  } warnings[] = {
      {mjWARN_CONTACTFULL, "the contact buffer was full (nconmax), so contacts were dropped"},
      {mjWARN_CNSTRFULL, "the constraint buffer was full (njmax), so constraints were dropped"},
      {mjWARN_BADQACC, "the accelerations became bad (NaN or huge) and the state was reset"},
      {mjWARN_BADQVEL, "the velocities became bad (NaN or huge) and the state was reset"},
      {mjWARN_BADQPOS, "the positions became bad (NaN or huge) and the state was reset"},
  };
  for (const auto& w : warnings)
    if (d->warning[w.index].number > 0)
      out.warnings.push_back(std::string(w.what) + " (" + std::to_string(d->warning[w.index].number) + " times; " +
                             std::to_string(m->nconmax) + " contacts, " + std::to_string(m->njmax) + " rows)");
  mj_deleteData(d);
  mj_deleteModel(m);
  return out;
}

}  // namespace g2p
