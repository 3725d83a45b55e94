// Private: a loop over independent items on the TBB pool that stops at
// nothing but reports the first failure in item order, so that an error is
// the same one a sequential loop would have returned.
#pragma once

#include <cstddef>
#include <vector>

#include <tbb/parallel_for.h>

#include "g2p/status.h"

namespace g2p::detail {

// Calls fn(i) for every i in [0, n), in parallel, one item at a time.
// Returns the Status of the lowest i that failed, or Ok.
template <typename Fn>
Status parallel_each(std::size_t n, Fn&& fn) {
  std::vector<Status> status(n);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) { status[i] = fn(i); });
  for (Status& s : status)
    if (!s.ok()) return s;
  return Status::Ok();
}

}  // namespace g2p::detail
