// One load_model in a fresh process, as `g2p` does it: the cost of parsing in
// a child process (ImportOptions::isolate_reader) without the warm heap that
// g2p_import_benchmark's loop keeps. docs/performance.md records the figures.
//
//   for i in 1 2 3; do for iso in 0 1; do build/bin/g2p_import_once FILE $iso; done; done
#include <chrono>
#include <cstdio>
#include <cstring>

#include "g2p/io.h"

int main(int argc, char** argv) {
  if (argc != 3 || (std::strcmp(argv[2], "0") != 0 && std::strcmp(argv[2], "1") != 0)) {
    std::fprintf(stderr, "usage: g2p_import_once MODEL 0|1   (1: parse in a child process)\n");
    return 2;
  }
  g2p::ImportOptions options;
  options.isolate_reader = argv[2][0] == '1';
  const auto start = std::chrono::steady_clock::now();
  g2p::Result<g2p::Model> model = g2p::load_model(argv[1], options);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!model.ok()) {
    std::fprintf(stderr, "%s\n", model.status().to_string().c_str());
    return 1;
  }
  std::printf("%s %s %.1f ms\n", argv[1], options.isolate_reader ? "child" : "in-process", ms);
  return 0;
}
