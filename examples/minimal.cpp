// Example: the whole Gen2Physics pipeline in one call, from a mesh file to a
// MuJoCo model (MJCF with one mesh per material part and exact inertia).
//
//   minimal MODEL OUTPUT_FOLDER
#include <g2p/g2p.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s MODEL OUTPUT_FOLDER\n", argv[0]);
    return 2;
  }
  g2p::PipelineOptions options;  // the offline defaults: hybrid, smooth, partition, table
  options.formats = {"mjcf"};
  g2p::Pipeline pipeline(options);
  g2p::Result<g2p::PipelineResult> result = pipeline.run_file(argv[1]);
  g2p::Status written = result.ok() ? g2p::write_pipeline_output(argv[2], *result, options) : result.status();
  if (!written.ok()) {
    std::fprintf(stderr, "error: %s\n", written.to_string().c_str());
    return 1;
  }
  std::printf("%s: %zu parts, %.3f kg -> %s/%s.xml\n", argv[1], result->asset.parts.size(), result->asset.total.mass_kg,
              argv[2], result->asset.name.c_str());
  return 0;
}
