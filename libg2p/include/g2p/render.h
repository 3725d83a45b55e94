// render: stage 1 of Gen2Physics. The model is rendered from several
// viewpoints (the paper uses 11); every view carries the RGB image a
// segmenter looks at and the face-ID buffer (the paper's "face index buffer")
// that says which triangle each pixel sees, plus depth, normal and the
// asset's own PBR channels per pixel.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "g2p/image.h"
#include "g2p/mesh.h"
#include "g2p/model.h"
#include "g2p/registry.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// A pinhole or orthographic camera in OpenCV's convention: the camera looks
// along its +z axis, x points right and y down in the image. Pixel (i, j)
// covers [i, i+1) x [j, j+1); its centre is (i + 0.5, j + 0.5).
struct G2P_API Camera {
  int width = 512;   // pixels
  int height = 512;  // pixels
  bool orthographic = false;
  // Perspective: focal lengths in pixels. Orthographic: pixels per metre.
  double fx = 512.0, fy = 512.0;
  double cx = 256.0, cy = 256.0;                           // principal point, pixels
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // world-from-camera: columns are the camera axes
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      // centre of projection (perspective), metres

  // A camera at `eye` looking at `target`; `up` is the world direction that
  // appears upwards in the image (it must not be parallel to the view).
  static Camera look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up, int width,
                        int height, double fov_y_deg);

  Eigen::Vector3d forward() const { return rotation.col(2); }
  Eigen::Matrix3d intrinsics() const;       // K
  Eigen::Matrix4d world_to_camera() const;  // extrinsics [R^T | -R^T position]
  Eigen::Matrix4d camera_to_world() const;

  // The ray through the continuous pixel coordinate (px, py); unit direction.
  void ray(double px, double py, Eigen::Vector3d& origin, Eigen::Vector3d& direction) const;
  // The continuous pixel coordinate of a world point, and its depth along +z (metres).
  Eigen::Vector2d project(const Eigen::Vector3d& world, double* depth = nullptr) const;

  // Checks sizes and finite, positive parameters; the message names the field.
  Status validate() const;
};

enum class ViewLayout {
  kSphere,     // top and bottom views plus two rings at +-30 deg elevation (the default)
  kFibonacci,  // spherical Fibonacci lattice: near-uniform directions for any count
  kTurntable,  // one ring at ViewOptions::elevation_deg
};

struct ViewOptions {
  int num_views = 11;  // the paper's count
  ViewLayout layout = ViewLayout::kSphere;
  int width = 512;          // pixels
  int height = 512;         // pixels
  double fov_y_deg = 40.0;  // perspective vertical field of view, degrees
  bool orthographic = false;
  double margin = 1.1;          // the bounding sphere's radius is scaled by this for framing
  double elevation_deg = 20.0;  // kTurntable only
};

// Cameras around the mesh, each framing its bounding sphere. In libg2p's
// frame (+Z up, imported glTF fronts face -Y) the first ring view looks at the
// front. kSphere with 11 views: top, bottom, 5 views at +30 deg, 4 at -30 deg.
G2P_API Result<std::vector<Camera>> make_views(const Mesh& mesh, const ViewOptions& options = {});

// A directional light that turns with the camera, so that every view of an
// object is lit alike. No shadows.
struct CameraLight {
  Eigen::Vector3f direction{0.f, 0.f, -1.f};  // towards the light in the camera's frame (x right, y down, z
                                              // forward); any length > 0 (normalised when rendering)
  float irradiance = 1.f;                     // >= 0; the studio key light is 2.4
};

// libg2p's studio set: key (irradiance 2.4) from the upper left in front of the
// object, fill (0.8) from the right, rim (1.0) from behind and above.
G2P_API std::vector<CameraLight> studio_lights();

struct RenderOptions {
  bool shade = true;                                      // the RGB image (Lambert + GGX under the studio lights)
  bool material_buffers = true;                           // base colour, metallic-roughness and transmission per pixel
  bool geometry_buffers = true;                           // depth and normal per pixel
  std::array<std::uint8_t, 3> background{200, 200, 200};  // sRGB, neutral grey
  int max_layers = 4;  // transparent surfaces composited per pixel (BLEND, transmission)
  int tile_size = 32;  // pixels; square tiles are rendered in parallel
  // The lights of the RGB image; empty: studio_lights(). The ambient sky,
  // ground and environment terms apply either way (render.md).
  std::vector<CameraLight> lights;
};

// One rendered view. Every buffer has the camera's size; background pixels
// have face_id -1, the background colour in rgb, depth +infinity and zero in
// the other buffers.
struct View {
  Camera camera;
  ImageI32 face_id;           // index into Mesh::triangles of the first surface seen
  ImageU8 rgb;                // 3 channels, sRGB (RenderOptions::shade)
  ImageF depth;               // metres along the camera's +z axis (geometry_buffers)
  ImageF normal;              // 3 channels, world-space unit normal facing the camera (geometry_buffers)
  ImageF base_color;          // 4 channels, linear RGBA: factor times texture (material_buffers)
  ImageF metallic_roughness;  // 2 channels: metallic, roughness (material_buffers)
  ImageF transmission;        // 1 channel (material_buffers)
};

// The render stage's interface. set_model prepares a model (acceleration
// structures); render_into draws one view of it. The model must stay alive and
// unchanged while the renderer uses it. Rendering is const and may run on
// several threads at once (each with its own View).
class G2P_API Renderer {
 public:
  virtual ~Renderer();
  virtual Status set_model(const Model& model) = 0;
  // Renders into `view`, reusing the memory its buffers already hold: a loop
  // over many cameras with one View allocates nothing after the first.
  // Buffers the options do not ask for are emptied.
  virtual Status render_into(const Camera& camera, const RenderOptions& options, View& view) const = 0;

  // Convenience: renders into a new View.
  Result<View> render(const Camera& camera, const RenderOptions& options = {}) const;
};

// Backends by name; libg2p registers "embree" (the default).
G2P_API Registry<Renderer>& renderer_registry();

// Renders every camera with `renderer` after set_model(model).
G2P_API Result<std::vector<View>> render_views(Renderer& renderer, const Model& model,
                                               const std::vector<Camera>& cameras, const RenderOptions& options = {});

// The view's normal buffer turned into its camera's frame (x right, y down, z
// away from the viewer: surfaces facing the camera have z < 0), 3 channels;
// zeros on the background. Empty when the view has no normal buffer
// (RenderOptions::geometry_buffers off). What a network that takes normals sees.
G2P_API ImageF camera_space_normals(const View& view);

// ---- Files -------------------------------------------------------------------

struct ViewFileOptions {
  bool buffers = false;  // also depth (.npy), normal, base colour, metallic-roughness, transmission
  int contact_sheet_columns = 4;
  int contact_sheet_tile = 256;  // pixels per view in the contact sheet
};

// Writes into `dir` (created if needed): view_XX_rgb.png, view_XX_faceid.png
// (face_id + 1 as a 24-bit little-endian integer in R, G, B; 0 = background),
// cameras.json and contact_sheet.png, plus the buffers if asked. Files are
// written under temporary names and renamed, so none is ever half-written.
G2P_API Status write_views(const std::string& dir, const std::vector<View>& views, const ViewFileOptions& options = {});

// The JSON written to cameras.json: intrinsics and extrinsics per view.
G2P_API std::string cameras_to_json(const std::vector<Camera>& cameras);
G2P_API Result<std::vector<Camera>> cameras_from_json(const std::string& json_text);

// The lossless face-ID encoding of view_XX_faceid.png (up to 16,777,214 faces).
G2P_API Result<ImageU8> encode_face_ids(const ImageI32& face_id);
G2P_API Result<ImageI32> decode_face_ids(const ImageU8& encoded);

// A grid of images scaled to `tile` pixels, `columns` wide; the first
// `numbered` of them (all when -1) carry their index in a corner.
G2P_API ImageU8 contact_sheet(const std::vector<const ImageU8*>& images, int columns, int tile, int numbered = -1);

}  // namespace g2p
