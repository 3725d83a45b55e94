// Private: what the MuJoCo checks share (mujoco_check.cpp defines them).
#pragma once

#include <mujoco/mujoco.h>

#include <string>

#include "g2p/status.h"

namespace g2p::detail {

// MuJoCo reports warnings through a global handler that, when the program has
// set none, appends them to MUJOCO_LOG.TXT in the working directory. The checks
// read mjData::warning instead, so while one runs, a program without its own
// handler gets none of those files. (A handler the program set is kept.)
class QuietMujocoWarnings {
 public:
  QuietMujocoWarnings() : previous_(mju_user_warning) {
    if (previous_ == nullptr) mju_user_warning = [](const char*) {};
  }
  ~QuietMujocoWarnings() { mju_user_warning = previous_; }
  QuietMujocoWarnings(const QuietMujocoWarnings&) = delete;
  QuietMujocoWarnings& operator=(const QuietMujocoWarnings&) = delete;

 private:
  void (*previous_)(const char*);
};

// A geom that collides with something (the exporter's visual geoms have
// contype and conaffinity 0).
inline bool collides(const mjModel* m, int geom) {
  return m->geom_contype[geom] != 0 || m->geom_conaffinity[geom] != 0;
}

// Calls f(x, y, z) for every vertex of every colliding mesh geom, in world
// coordinates, in the state `d` holds.
template <typename F>
void for_each_collision_vertex(const mjModel* m, const mjData* d, F f) {
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] != mjGEOM_MESH || !collides(m, g)) continue;
    const int mesh = m->geom_dataid[g];
    const float* v = m->mesh_vert + 3 * m->mesh_vertadr[mesh];
    const mjtNum* pos = d->geom_xpos + 3 * g;
    const mjtNum* rot = d->geom_xmat + 9 * g;  // row-major
    for (int i = 0; i < m->mesh_vertnum[mesh]; ++i) {
      const float* p = v + 3 * i;
      f(pos[0] + rot[0] * p[0] + rot[1] * p[1] + rot[2] * p[2], pos[1] + rot[3] * p[0] + rot[4] * p[1] + rot[5] * p[2],
        pos[2] + rot[6] * p[0] + rot[7] * p[1] + rot[8] * p[2]);
    }
  }
}

// The version MuJoCo reports, as "MuJoCo 2.2.2".
inline std::string engine_name() {
  return "MuJoCo " + std::to_string(mj_version() / 100) + "." + std::to_string(mj_version() / 10 % 10) + "." +
         std::to_string(mj_version() % 10);
}

// The MJCF text of `mjcf_path` with its meshdir made absolute, so that a
// changed copy loads from anywhere.
Result<std::string> mjcf_with_absolute_meshdir(const std::string& mjcf_path);

// Loads MJCF text from a temporary folder (removed at once); the model is
// the caller's to delete. `what` names the source in errors.
Result<mjModel*> load_mjcf_text(const std::string& xml, const std::string& what);

}  // namespace g2p::detail
