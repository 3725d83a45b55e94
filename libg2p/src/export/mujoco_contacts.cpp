// check_contacts_in_mujoco: probe balls dropped onto the fixed object in
// MuJoCo, to see where the exported collision geometry lets things rest.
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "export/mujoco_support.h"
#include "g2p/export.h"

namespace g2p {
namespace {

// Bounds of the model's colliding mesh vertices in the world at qpos0 (the
// body frame is the object's frame there).
Eigen::AlignedBox3d collision_bounds(const mjModel* m) {
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  Eigen::AlignedBox3d box;
  detail::for_each_collision_vertex(m, d, [&](double x, double y, double z) { box.extend(Eigen::Vector3d(x, y, z)); });
  mj_deleteData(d);
  return box;
}

// The colliding geometry seen from straight above: a ray down through each
// cell's centre (mj_ray over the geom groups that hold colliding geoms).
HeightMap height_map(const mjModel* m, const Eigen::AlignedBox3d& box, int cells) {
  HeightMap map;
  const Eigen::Vector3d size = box.sizes();
  map.cell_m = std::max(size.x(), size.y()) / cells;
  if (!(map.cell_m > 0)) return map;
  map.width = std::max(1, static_cast<int>(std::ceil(size.x() / map.cell_m - 1e-9)));
  map.height = std::max(1, static_cast<int>(std::ceil(size.y() / map.cell_m - 1e-9)));
  map.origin = box.min().head<2>();
  map.floor_z = box.min().z();
  mjtByte groups[mjNGROUP] = {0};
  for (int g = 0; g < m->ngeom; ++g)
    if (detail::collides(m, g) && m->geom_group[g] >= 0 && m->geom_group[g] < mjNGROUP) groups[m->geom_group[g]] = 1;
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  const double top = box.max().z() + 0.01 + 0.01 * size.z();
  map.z.assign(static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height),
               std::numeric_limits<double>::quiet_NaN());
  const mjtNum down[3] = {0, 0, -1};
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const Eigen::Vector2d c = map.centre(x, y);
      const mjtNum from[3] = {c.x(), c.y(), top};
      int geom = -1;
      const mjtNum t = mj_ray(m, d, from, down, groups, 1, -1, &geom);
      if (geom >= 0 && t >= 0 && detail::collides(m, geom))
        map.z[static_cast<std::size_t>(y) * static_cast<std::size_t>(map.width) + static_cast<std::size_t>(x)] =
            top - t;
    }
  mj_deleteData(d);
  return map;
}

constexpr int kHeightMapCells = 96;  // along the longer side of the object's top view

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

}  // namespace

Result<ContactCheck> check_contacts_in_mujoco(const std::string& mjcf_path, const ContactCheckOptions& o) {
  const detail::QuietMujocoWarnings quiet;
  if (o.grid < 0 || o.grid > 50) return Status::InvalidArgument("--balls must be 0..50 (balls per side of the grid)");
  if (o.grid == 0 && o.points.empty() && !o.places)
    return Status::InvalidArgument("no probe balls: give --balls N or --at X,Y, or leave out --no-places");
  if (!(o.ball_radius_m >= 0) || !(o.seconds > 0) || !(o.ball_density_kg_m3 > 0) || !(o.rest_speed_m_s > 0) ||
      !(o.ball_rolling_friction_m >= 0) || !(o.ball_friction >= 0))
    return Status::InvalidArgument(
        "contact check: the ball radius, friction and rolling friction must be >= 0, the time, the density and the "
        "rest speed > 0");
  Result<std::string> text = detail::mjcf_with_absolute_meshdir(mjcf_path);
  if (!text.ok()) return text.status();
  std::string xml = *text;

  ContactCheck out;
  out.engine = detail::engine_name();
  {
    Result<mjModel*> m = detail::load_mjcf_text(xml, mjcf_path);
    if (!m.ok()) return m.status();
    if ((*m)->nbody < 2) {
      mj_deleteModel(*m);
      return Status::InvalidArgument(mjcf_path + ": no body");
    }
    out.object_bounds = collision_bounds(*m);
    if (!out.object_bounds.isEmpty()) out.height_map = height_map(*m, out.object_bounds, kHeightMapCells);
    mj_deleteModel(*m);
  }
  if (out.object_bounds.isEmpty())
    return Status::InvalidArgument(mjcf_path + ": the body has no colliding mesh geom (nothing to drop balls on)");

  // The object fixed in place: its free joint removed.
  const std::size_t free = xml.find("<freejoint");
  if (free != std::string::npos) {
    const std::size_t end = xml.find("/>", free);
    const std::size_t line_start = xml.rfind('\n', free);
    if (end == std::string::npos) return Status::ParseError(mjcf_path + ": an unterminated <freejoint>");
    xml.erase(line_start + 1, end + 2 - line_start);
  }
  const Eigen::Vector3d lo = out.object_bounds.min(), hi = out.object_bounds.max();
  const double size = out.object_bounds.sizes().maxCoeff();
  const double r = o.ball_radius_m > 0 ? o.ball_radius_m : std::max(0.005, 0.02 * size);
  const double mass = o.ball_density_kg_m3 * 4.0 / 3.0 * M_PI * r * r * r;
  const double inertia = 0.4 * mass * r * r;
  std::vector<Eigen::Vector2d> starts = o.points;
  for (int i = 0; i < o.grid; ++i)
    for (int j = 0; j < o.grid; ++j)
      starts.emplace_back(lo.x() + (hi.x() - lo.x()) * (i + 0.5) / o.grid,
                          lo.y() + (hi.y() - lo.y()) * (j + 0.5) / o.grid);
  std::vector<int> start_place(starts.size(), -1);
  if (o.places && out.height_map.width > 0 && out.height_map.height > 0) {  // a map: the top view has an area
    RestingPlaceOptions po = o.place_options;
    po.probe_clearance_m = std::max(po.probe_clearance_m, r);
    Result<std::vector<RestingPlace>> places = find_resting_places(out.height_map, po);
    if (!places.ok()) return places.status().with_context(mjcf_path);
    for (RestingPlace& p : *places) {
      for (const Eigen::Vector2d& at : p.probes) {
        starts.push_back(at);
        start_place.push_back(static_cast<int>(out.places.size()));
      }
      PlaceProbe probe;
      probe.place = std::move(p);
      probe.dropped = static_cast<int>(probe.place.probes.size());
      out.places.push_back(std::move(probe));
    }
  }
  if (starts.empty()) return Status::InvalidArgument(mjcf_path + ": no probe balls (no grid, points or places)");
  const double start_z = hi.z() + 2.0 * r;

  // Balls: contype 2, conaffinity 1 touch the object and the floor (1/1)
  // but not each other. They carry their own inertia, since the file says
  // inertiafromgeom="false"; otherwise they are MuJoCo's default sphere (a
  // user's ball), so that the object's contact parameters decide whether they
  // stay. The floor has rolling friction (condim 6, 2 mm), so that a ball on
  // it stops instead of rolling for ever.
  std::string world = "    <geom name=\"g2p_floor\" type=\"plane\" size=\"0 0 1\" pos=\"0 0 " + num(lo.z()) +
                      "\" condim=\"6\" friction=\"1 0.005 0.002\"/>\n";
  const std::string ball_contact =
      o.ball_rolling_friction_m > 0
          ? " condim=\"6\" friction=\"" + num(o.ball_friction) + " 0.005 " + num(o.ball_rolling_friction_m) + "\""
          : " friction=\"" + num(o.ball_friction) + " 0.005 0.0001\"";
  std::string balls;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::string name = "g2p_probe_" + std::to_string(k);
    balls += "    <body name=\"" + name + "\" pos=\"" + num(starts[k].x()) + " " + num(starts[k].y()) + " " +
             num(start_z) + "\">\n      <freejoint/>\n      <inertial pos=\"0 0 0\" mass=\"" + num(mass) +
             "\" diaginertia=\"" + num(inertia) + " " + num(inertia) + " " + num(inertia) +
             "\"/>\n      <geom name=\"" + name + "\" type=\"sphere\" size=\"" + num(r) +
             "\" contype=\"2\" conaffinity=\"1\"" + ball_contact + "/>\n    </body>\n";
  }
  const std::string open = "  <worldbody>\n", close = "  </worldbody>";
  const std::size_t wb = xml.find(open);
  const std::size_t we = xml.rfind(close);
  if (wb == std::string::npos || we == std::string::npos || we < wb)
    return Status::ParseError(mjcf_path + ": no <worldbody> as libg2p writes it");
  xml.insert(we, balls);
  xml.insert(wb + open.size(), world);

  Result<mjModel*> loaded = detail::load_mjcf_text(xml, mjcf_path + " with probe balls");
  if (!loaded.ok()) return loaded.status();
  mjModel* m = *loaded;
  mjData* d = mj_makeData(m);
  const int floor = mj_name2id(m, mjOBJ_GEOM, "g2p_floor");
  std::vector<RestingPlace> places;
  for (const PlaceProbe& p : out.places) places.push_back(p.place);
  const int steps = static_cast<int>(std::ceil(o.seconds / m->opt.timestep));
  for (int i = 0; i < steps; ++i) mj_step(m, d);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::string name = "g2p_probe_" + std::to_string(k);
    const int body = mj_name2id(m, mjOBJ_BODY, name.c_str());
    const int geom = mj_name2id(m, mjOBJ_GEOM, name.c_str());
    BallProbe b;
    b.start = starts[k];
    b.place = start_place[k];
    b.radius_m = r;
    b.rest = Eigen::Vector3d(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
    b.height_above_floor_m = b.rest.z() - r - lo.z();
    const int dof = m->body_dofadr[body];
    b.final_speed_m_s = Eigen::Vector3d(d->qvel[dof], d->qvel[dof + 1], d->qvel[dof + 2]).norm();
    b.at_rest = std::isfinite(b.final_speed_m_s) && b.final_speed_m_s < o.rest_speed_m_s;
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact& con = d->contact[c];
      if (con.geom1 != geom && con.geom2 != geom) continue;
      const int other = con.geom1 == geom ? con.geom2 : con.geom1;
      if (other == floor)
        b.on_floor = true;
      else if (m->geom_bodyid[other] == 1)
        b.on_object = true;
    }
    if (b.on_object)
      b.rests_in = resting_place_at(out.height_map, places, b.rest - Eigen::Vector3d(0, 0, r), std::max(r, 0.01));
    if (b.place >= 0 && b.rests_in == b.place && b.at_rest) ++out.places[static_cast<std::size_t>(b.place)].stayed;
    out.balls.push_back(b);
  }
  mj_deleteData(d);
  mj_deleteModel(m);

  Result<EngineCheck> drop = check_in_mujoco(mjcf_path, o.drop_height_m, 2.0);
  if (!drop.ok()) return drop.status();
  out.drop = *drop;
  out.object_above_plane = !out.drop.dropped || (out.drop.finite && out.drop.resting_lowest_m > -0.01);
  return out;
}

}  // namespace g2p
