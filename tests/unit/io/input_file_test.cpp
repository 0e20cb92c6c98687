// Loaders refuse what is not a regular file before they open it: a FIFO
// (which would block the open until a writer came), a directory, a device;
// each error names the path and what it is.
#include "haarcast/io/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <future>

#include <gtest/gtest.h>

#include "../test_files.h"
#include "haarcast/io/environment.h"
#include "haarcast/io/image.h"
#include "haarcast/io/merl.h"
#include "haarcast/io/mesh_io.h"

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;
using haarcast::testing::TempDir;
using namespace std::chrono_literals;

// The loader's error, or "hung" when it blocked on `fifo` for 5 s (then a
// writer is opened and closed so that the loader's thread ends).
std::string errorOf(const std::function<void()>& load, const fs::path& fifo) {
  auto result = std::async(std::launch::async, [&] {
    try {
      load();
      return std::string("no error");
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
  });
  if (result.wait_for(5s) == std::future_status::ready) return result.get();
  const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
  if (fd >= 0) ::close(fd);
  result.wait();
  return "hung";
}

TEST(InputFile, LoadersRefuseAFifoNamingItInsteadOfBlocking) {
  TempDir tmp("haarcast-input-file-test-");
  for (const char* name : {"probe.hdr", "probe.pfm", "probe.exr", "mesh.ply", "mesh.obj", "brdf.binary"}) {
    const fs::path fifo = tmp / name;
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << fifo;
  }
  const auto path = [&](const char* name) { return (tmp / name).string(); };
  const std::pair<const char*, std::function<void()>> loads[] = {
      {"probe.hdr", [&] { loadEnvironment(path("probe.hdr")); }},
      {"probe.pfm", [&] { loadEnvironment(path("probe.pfm")); }},
      {"probe.exr", [&] { loadEnvironment(path("probe.exr")); }},
      {"mesh.ply", [&] { loadMesh(path("mesh.ply")); }},
      {"mesh.obj", [&] { loadMesh(path("mesh.obj")); }},
      {"brdf.binary", [&] { loadMerlBrdf(path("brdf.binary")); }},
  };
  for (const auto& [name, load] : loads) {
    const std::string error = errorOf(load, tmp / name);
    EXPECT_NE(error.find(path(name)), std::string::npos) << name << ": " << error;
    EXPECT_NE(error.find("is a FIFO (named pipe), not a regular file"), std::string::npos) << name << ": " << error;
  }
}

TEST(InputFile, DirectoriesAndDevicesAreNamedToo) {
  TempDir tmp("haarcast-input-file-test-");
  fs::create_directories(tmp / "dir.ply");
  EXPECT_EQ(whyNotRegularFile((tmp / "dir.ply").string()), "is a directory, not a regular file");
  EXPECT_EQ(whyNotRegularFile("/dev/zero"), "is a character device, not a regular file");
  EXPECT_EQ(whyNotRegularFile((tmp / "none").string()), "does not exist");
  try {
    loadMesh((tmp / "dir.ply").string());
    ADD_FAILURE() << "a directory loaded as a mesh";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  EXPECT_THROW(requireRegularFile("/dev/zero", "scene file"), std::runtime_error);
  const fs::path file = tmp / "f";
  std::ofstream(file) << "x";
  EXPECT_EQ(whyNotRegularFile(file.string()), std::nullopt);
  fs::create_symlink(file, tmp / "link");
  EXPECT_EQ(whyNotRegularFile((tmp / "link").string()), std::nullopt) << "a link to a file is a file";
}

}  // namespace
}  // namespace haarcast::io
