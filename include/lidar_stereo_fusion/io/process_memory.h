// How the process's heap returns freed memory, for the nodelet and the tools (the core sets none).
// ROS-free.
//
// Every frame allocates its maps afresh (a KITTI frame: about 40 maps of 0.5-2 MB). glibc serves
// blocks above its mmap threshold (128 KB to start) with new mappings and hands freed memory at the
// top of a heap back to the kernel beyond its trim threshold, so the next frame's maps fault their
// pages in again, zeroed by the kernel: about 4 ms of a 50 ms `live` frame on KITTI
// (doc/performance.md). Real-time Linux guides keep freed memory instead (mallopt).
#pragma once

#include <string>

namespace lidar_stereo_fusion {

/// The largest block glibc still serves from a heap once keepFreedMemory() ran [bytes] (its own
/// upper limit for M_MMAP_THRESHOLD on 64-bit).
constexpr int kHeapBlockLimit = 32 * 1024 * 1024;
/// Free memory a heap keeps at its top once keepFreedMemory() ran [bytes].
constexpr int kKeptFreeMemory = 512 * 1024 * 1024;

/// Blocks up to kHeapBlockLimit come from the heap and up to kKeptFreeMemory of freed memory stays
/// with the process: a frame reuses the pages of the frame before. The resident size stays near
/// its peak. Returns false (and the reason in `problem`, if given) where the C library is not
/// glibc or refuses; nothing changes then.
bool keepFreedMemory(std::string* problem = nullptr);

}  // namespace lidar_stereo_fusion
