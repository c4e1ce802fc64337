#include "bag_files.h"

#include <signal.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace lidar_stereo_fusion {

namespace {

std::string hostName() {
  char name[256] = {0};
  if (::gethostname(name, sizeof(name) - 1) != 0) return "localhost";
  std::string host(name);
  for (char& c : host) {  // the name is part of a file name
    if (c == '/' || c == '~' || c == '@') c = '_';
  }
  return host;
}

bool digits(const std::string& s) {
  return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
}

bool processRuns(long pid) {
  return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

/// The writer of a temporary file: pid and host ("" for the older names, which had no host), or
/// pid -1 when `name` is no temporary file of ours.
std::pair<long, std::string> tempWriter(const std::string& name) {
  const std::string end = ".tmp";
  if (name.size() > 1 && name[0] == '.' && name.size() > end.size() &&
      name.compare(name.size() - end.size(), end.size(), end) == 0) {
    const std::string middle = name.substr(1, name.size() - 1 - end.size());
    const auto tilde = middle.rfind('~');
    const auto at = tilde == std::string::npos ? std::string::npos : middle.find('@', tilde);
    if (at != std::string::npos && digits(middle.substr(tilde + 1, at - tilde - 1))) {
      return {std::stol(middle.substr(tilde + 1, at - tilde - 1)), middle.substr(at + 1)};
    }
  }
  // Older names: "<name>.tmp<pid>" and "<name>.tmp<pid>.png".
  std::string stem = name;
  if (stem.size() > 4 && stem.compare(stem.size() - 4, 4, ".png") == 0) {
    stem.resize(stem.size() - 4);
  }
  const auto tmp = stem.rfind(".tmp");
  if (tmp != std::string::npos && digits(stem.substr(tmp + 4))) {
    return {std::stol(stem.substr(tmp + 4)), ""};
  }
  return {-1, ""};
}

std::string errnoText() { return std::strerror(errno); }

}  // namespace

std::string tempPath(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() / ("." + p.filename().string() + "~" + std::to_string(::getpid()) + "@" +
                             hostName() + ".tmp"))
      .string();
}

int removeStaleTemps(const std::string& folder, bool all) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return 0;
  const std::string host = hostName();
  int removed = 0;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const auto [pid, writer_host] = tempWriter(entry.path().filename().string());
    if (pid < 0 || !entry.is_regular_file(ec)) continue;
    const bool here = writer_host.empty() || writer_host == host;
    if (!all && (!here || processRuns(pid))) continue;
    if (fs::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

void checkOutputsAgainstInputs(const std::vector<LabelledPath>& outputs,
                               const std::vector<LabelledPath>& inputs) {
  std::error_code ec;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const LabelledPath& out = outputs[i];
    for (const LabelledPath& in : inputs) {
      if (fs::exists(out.path, ec) && fs::exists(in.path, ec) &&
          fs::equivalent(out.path, in.path, ec)) {
        throw std::runtime_error("refusing to write " + out.label + " " + out.path +
                                 ": it is the " + in.label + " " + in.path +
                                 " (the same file, or a link to it); choose another " + out.label);
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      const LabelledPath& other = outputs[j];
      const bool same = fs::exists(out.path, ec) && fs::exists(other.path, ec)
                            ? fs::equivalent(out.path, other.path, ec)
                            : fs::weakly_canonical(fs::absolute(out.path), ec) ==
                                  fs::weakly_canonical(fs::absolute(other.path), ec);
      if (same) {
        throw std::runtime_error(other.label + " " + other.path + " and " + out.label + " " +
                                 out.path + " are the same file: one would overwrite the other");
      }
    }
  }
}

void requireWritableFolder(const std::string& folder, const std::string& label) {
  std::error_code ec;
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec)) {
    throw std::runtime_error("cannot write in " + folder + " (" + label +
                             "): it is a file, not a folder");
  }
  fs::create_directories(folder, ec);
  if (ec) {
    throw std::runtime_error("cannot write in " + folder + " (" + label +
                             "): cannot create it: " + ec.message());
  }
  const std::string probe = tempPath((fs::path(folder) / "write_check").string());
  {
    std::ofstream out(probe, std::ios::binary);
    if (!out) {
      throw std::runtime_error("cannot write in " + folder + " (" + label + "): " + errnoText());
    }
  }
  fs::remove(probe, ec);
}

bool isStampFile(const std::string& name, const std::string& ext) {
  if (name.size() <= ext.size() || name.compare(name.size() - ext.size(), ext.size(), ext) != 0) {
    return false;
  }
  const std::string stem = name.substr(0, name.size() - ext.size());
  const auto dot = stem.find('.');
  return dot != std::string::npos && digits(stem.substr(0, dot)) && stem.size() - dot - 1 == 9 &&
         digits(stem.substr(dot + 1));
}

int removeEarlierOutputs(const std::string& dir) {
  int removed = 0;
  std::error_code ec;
  const auto clear = [&](const fs::path& folder, const std::string& ext) {
    if (!fs::is_directory(folder, ec)) return;
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      if (isStampFile(entry.path().filename().string(), ext) && fs::remove(entry.path(), ec)) {
        ++removed;
      }
    }
  };
  clear(dir, ".png");
  clear(fs::path(dir) / "disparity", ".png");
  clear(fs::path(dir) / "confidence", ".png");
  clear(fs::path(dir) / "cloud", ".pcd");
  for (const char* name : {"frames.csv", "frames.csv.partial", "manifest.txt"}) {
    if (fs::remove(fs::path(dir) / name, ec)) ++removed;
  }
  return removed;
}

bool holdsOutputs(const std::string& dir) {
  std::error_code ec;
  if (fs::exists(fs::path(dir) / "frames.csv", ec)) return true;
  if (!fs::is_directory(dir, ec)) return false;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (isStampFile(entry.path().filename().string(), ".png")) return true;
  }
  return false;
}

void writeBytesAtomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = tempPath(path);
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error("cannot write " + path + ": " + errnoText());
    out << bytes;
    if (!out.flush()) {
      const std::string reason = errnoText();
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("cannot write " + path + ": " + reason);
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    const std::string reason = ec.message();
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write " + path + ": rename failed: " + reason);
  }
}

}  // namespace lidar_stereo_fusion
