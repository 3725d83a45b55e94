// check_in_mujoco and check_contacts_in_mujoco when libg2p is built without MuJoCo (G2P_WITH_MUJOCO=OFF).
#include "g2p/export.h"

namespace g2p {

bool have_mujoco() { return false; }

Result<EngineCheck> check_in_mujoco(const std::string& mjcf_path, double, double) {
  return Status::Unavailable(mjcf_path + ": libg2p was built without MuJoCo (G2P_WITH_MUJOCO=OFF)");
}

Result<ContactCheck> check_contacts_in_mujoco(const std::string& mjcf_path, const ContactCheckOptions&) {
  return Status::Unavailable(mjcf_path + ": libg2p was built without MuJoCo (G2P_WITH_MUJOCO=OFF)");
}

}  // namespace g2p
