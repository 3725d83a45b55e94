// urdf_text: the asset as a URDF, built with urdfdom's model types and written
// by its exporter (so what ROS tools parse is what urdfdom writes). One link
// with the combined inertial, a visual element per part and a collision
// element per convex hull. urdfdom writes numbers with six digits, which can
// break a thin object's triangle inequality, so the inertial is rewritten with
// nine; a <mujoco> block lets MuJoCo's URDF importer find the meshes.
#include <tinyxml.h>
#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#include <cstdio>
#include <memory>

#include "export/asset_names.h"
#include "g2p/export.h"

namespace g2p {

namespace {

std::string precise(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

// Rewrites the link's <inertial> with nine significant digits, enough for the
// principal moments to keep A + B >= C after a reader parses them.
Status write_inertial_precisely(TiXmlDocument& doc, const MassProperties& m) {
  TiXmlElement* robot = doc.FirstChildElement("robot");
  TiXmlElement* link = robot != nullptr ? robot->FirstChildElement("link") : nullptr;
  TiXmlElement* inertial = link != nullptr ? link->FirstChildElement("inertial") : nullptr;
  TiXmlElement* origin = inertial != nullptr ? inertial->FirstChildElement("origin") : nullptr;
  TiXmlElement* mass = inertial != nullptr ? inertial->FirstChildElement("mass") : nullptr;
  TiXmlElement* inertia = inertial != nullptr ? inertial->FirstChildElement("inertia") : nullptr;
  if (origin == nullptr || mass == nullptr || inertia == nullptr)
    return Status::Internal("urdfdom wrote no <inertial> with origin, mass and inertia");
  const Eigen::Vector3d& c = m.center_of_mass;
  origin->SetAttribute("xyz", precise(c.x()) + " " + precise(c.y()) + " " + precise(c.z()));
  mass->SetAttribute("value", precise(m.mass_kg));
  const char* names[6] = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"};
  const double values[6] = {m.inertia(0, 0), m.inertia(0, 1), m.inertia(0, 2),
                            m.inertia(1, 1), m.inertia(1, 2), m.inertia(2, 2)};
  for (int i = 0; i < 6; ++i) inertia->SetAttribute(names[i], precise(values[i]));
  return Status::Ok();
}

}  // namespace

Result<std::string> urdf_text(const SimulationAsset& a) {
  urdf::ModelInterface model;
  model.name_ = a.name;
  auto link = std::make_shared<urdf::Link>();
  link->name = a.name;
  auto inertial = std::make_shared<urdf::Inertial>();
  const MassProperties& m = a.total;
  inertial->origin.position = urdf::Vector3(m.center_of_mass.x(), m.center_of_mass.y(), m.center_of_mass.z());
  inertial->mass = m.mass_kg;
  inertial->ixx = m.inertia(0, 0);
  inertial->ixy = m.inertia(0, 1);
  inertial->ixz = m.inertia(0, 2);
  inertial->iyy = m.inertia(1, 1);
  inertial->iyz = m.inertia(1, 2);
  inertial->izz = m.inertia(2, 2);
  link->inertial = inertial;
  for (const AssetPart& p : a.parts) {
    auto material = std::make_shared<urdf::Material>();
    material->name = p.material;
    material->color.r = static_cast<float>(p.rgba[0]);
    material->color.g = static_cast<float>(p.rgba[1]);
    material->color.b = static_cast<float>(p.rgba[2]);
    material->color.a = static_cast<float>(p.rgba[3]);
    model.materials_[material->name] = material;

    auto visual_mesh = std::make_shared<urdf::Mesh>();
    visual_mesh->filename = "meshes/" + p.name + "_visual.obj";
    visual_mesh->scale = urdf::Vector3(1, 1, 1);
    auto visual = std::make_shared<urdf::Visual>();
    visual->name = p.name + "_visual";
    visual->geometry = visual_mesh;
    visual->material_name = material->name;
    visual->material = material;
    link->visual_array.push_back(visual);

    for (std::size_t k = 0; k < p.collision.hulls.size(); ++k) {
      auto hull_mesh = std::make_shared<urdf::Mesh>();
      hull_mesh->filename = "meshes/" + detail::hull_name(p, k) + ".obj";
      hull_mesh->scale = urdf::Vector3(1, 1, 1);
      auto collision = std::make_shared<urdf::Collision>();
      collision->name = detail::hull_name(p, k);
      collision->geometry = hull_mesh;
      link->collision_array.push_back(collision);
    }
  }
  if (!link->visual_array.empty()) link->visual = link->visual_array.front();
  if (!link->collision_array.empty()) link->collision = link->collision_array.front();
  model.links_[link->name] = link;
  model.root_link_ = link;

  std::unique_ptr<TiXmlDocument> doc(urdf::exportURDF(model));
  if (!doc) return Status::Internal("urdfdom could not export the model");
  G2P_RETURN_IF_ERROR(write_inertial_precisely(*doc, a.total));
  // MuJoCo's URDF importer drops mesh paths' folders and fuses a link with no
  // joint into the world unless told not to.
  if (TiXmlElement* robot = doc->FirstChildElement("robot")) {
    TiXmlElement mujoco("mujoco");
    TiXmlElement compiler("compiler");
    compiler.SetAttribute("strippath", "false");
    compiler.SetAttribute("discardvisual", "true");
    compiler.SetAttribute("fusestatic", "false");  // keep the link a body, with its inertial
    mujoco.InsertEndChild(compiler);
    if (robot->FirstChild() != nullptr)
      robot->InsertBeforeChild(robot->FirstChild(), mujoco);
    else
      robot->InsertEndChild(mujoco);
  }
  TiXmlPrinter printer;
  printer.SetIndent("  ");
  doc->Accept(&printer);
  return "<?xml version=\"1.0\"?>\n<!-- Written by libg2p (Gen2Physics) through urdfdom. Metres, kilograms; +Z up. "
         "-->\n" +
         std::string(printer.CStr());
}

}  // namespace g2p
