// How the process's heap returns freed memory (readings in process_memory.h).
#include "lidar_stereo_fusion/io/process_memory.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace lidar_stereo_fusion {

bool keepFreedMemory(std::string* problem) {
#if defined(__GLIBC__)
  // Setting either threshold also ends glibc's own adjustment of both (mallopt(3)).
  if (mallopt(M_MMAP_THRESHOLD, kHeapBlockLimit) == 1 &&
      mallopt(M_TRIM_THRESHOLD, kKeptFreeMemory) == 1) {
    return true;
  }
  if (problem) *problem = "glibc refused mallopt(M_MMAP_THRESHOLD / M_TRIM_THRESHOLD)";
  return false;
#else
  if (problem) *problem = "the C library is not glibc: freed memory is returned as it decides";
  return false;
#endif
}

}  // namespace lidar_stereo_fusion
