// The files bag_runner writes, kept apart from what it reads and from half-written states:
//  * every output path is compared with every input (the same file, a hard link, a symbolic
//    link: std::filesystem::equivalent) before anything is opened for writing;
//  * every file is written under a temporary name and renamed (a rename replaces a directory
//    entry, never the file a link points to); temporary names are hidden, never end in .png or
//    .pcd, and say which process wrote them, so that a later run removes those of dead processes;
//  * an output folder is proven writable before any work.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace lidar_stereo_fusion {

/// A temporary name beside `path` (same folder: the rename is atomic): ".<name>~<pid>@<host>.tmp".
std::string tempPath(const std::string& path);

/// Removes the temporary files in `folder` (not recursive) whose writer is gone: this host's
/// processes that no longer run, and, with `all` (no other writer can be running: lsf_batch before
/// it starts a bag's tasks), every one; also the older names "<name>.tmp<pid>" and
/// "<name>.tmp<pid>.png" of dead processes. Returns how many were removed.
int removeStaleTemps(const std::string& folder, bool all);

/// A labelled path: what it is for the messages ("--out-bag", "input bag", ...) and the path.
struct LabelledPath {
  std::string label, path;
};

/// Throws std::runtime_error naming both when an output is an input (equivalent: same file, hard
/// link or symbolic link to it) or two outputs are one file. Outputs that do not exist yet are
/// compared by their absolute, normalised paths.
void checkOutputsAgainstInputs(const std::vector<LabelledPath>& outputs,
                               const std::vector<LabelledPath>& inputs);

/// Creates `folder` (and parents) and writes and removes a temporary file in it. Throws
/// std::runtime_error "cannot write in <folder> (<label>): <reason>" when it cannot.
void requireWritableFolder(const std::string& folder, const std::string& label);

/// "<sec>.<nsec, 9 digits><ext>": a per-set output file of bag_runner.
bool isStampFile(const std::string& file_name, const std::string& ext);

/// The outputs of an earlier run in `dir` (stamp PNGs, disparity/ and confidence/ PNGs, cloud/
/// PCDs, frames.csv and its .partial, manifest.txt), for --force. Returns how many were removed.
int removeEarlierOutputs(const std::string& dir);

/// Whether `dir` holds any output of bag_runner (a stamp PNG or frames.csv).
bool holdsOutputs(const std::string& dir);

/// Writes `bytes` to `path` through tempPath() and a rename. Throws std::runtime_error naming the
/// path and the reason (errno's text).
void writeBytesAtomically(const std::string& path, const std::string& bytes);

}  // namespace lidar_stereo_fusion
