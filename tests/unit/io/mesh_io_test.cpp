// OBJ and PLY loading: small hand-written files in every encoding the loaders
// claim, the real models of ../shared/data, and the corrupt files a loader
// must refuse with a message that names the file and the problem.
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "haarcast/core/mesh.h"
#include "haarcast/io/mesh_io.h"

#include "../test_files.h"

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;
using haarcast::testing::TempDir;
using haarcast::testing::writeFile;

// A fresh directory per test, removed afterwards; the name also carries
// GoogleTest's random seed.
std::string tempPrefix() {
  return "haarcast-mesh-test-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-";
}

// Expects `f` to throw std::runtime_error whose message has every one of `parts`.
template <typename F>
void expectError(const F& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one mentioning \"" << parts.front() << "\"";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(what.find(part), std::string::npos) << "message \"" << what << "\" lacks \"" << part << "\"";
    }
  }
}

double totalArea(const Mesh& m) {
  double area = 0.0;
  for (const glm::uvec3& t : m.triangles) {
    const glm::dvec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

void expectUnitNormals(const Mesh& m) {
  ASSERT_EQ(m.normals.size(), m.positions.size());
  for (std::size_t i = 0; i < m.normals.size(); ++i) {
    ASSERT_NEAR(glm::length(glm::dvec3(m.normals[i])), 1.0, 1e-5) << "normal " << i;
  }
}

// ------------------------------------------------------------ PLY writers

// A unit square in the XZ plane (y = 0) as one quad, with a colour per vertex
// and an extra element between vertex and face — what real exporters write.
struct PlyVertex {
  float x, y, z, nx, ny, nz;
  std::uint8_t r, g, b;
};
const std::vector<PlyVertex> kSquare = {
    {0, 0, 0, 0, 2, 0, 255, 0, 0},  // a normal of length 2: the loader must normalise it
    {0, 0, 1, 0, 1, 0, 0, 255, 0},
    {1, 0, 1, 0, 1, 0, 0, 0, 255},
    {1, 0, 0, 0, 1, 0, 9, 9, 9},
};

std::string asciiSquarePly(const std::string& eol = "\n") {
  std::string s = "ply" + eol + "format ascii 1.0" + eol + "comment hand-written" + eol + "element vertex 4" + eol +
                  "property float x" + eol + "property float y" + eol + "property float z" + eol +
                  "property float nx" + eol + "property float ny" + eol + "property float nz" + eol +
                  "property uchar red" + eol + "property uchar green" + eol + "property uchar blue" + eol +
                  "element edge 1" + eol + "property int vertex1" + eol + "property int vertex2" + eol +
                  "element face 1" + eol + "property uchar flags" + eol +
                  "property list uchar int vertex_indices" + eol + "property list uchar float texcoord" + eol +
                  "end_header" + eol;
  for (const PlyVertex& v : kSquare) {
    s += std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + " " + std::to_string(v.nx) +
         " " + std::to_string(v.ny) + " " + std::to_string(v.nz) + " " + std::to_string(v.r) + " " +
         std::to_string(v.g) + " " + std::to_string(v.b) + eol;
  }
  s += "0 1" + eol;
  s += "7 4 0 1 2 3 2 0.5 0.5" + eol;
  return s;
}

template <typename T>
void putBinary(std::string& out, T value, bool bigEndian) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(raw, raw + sizeof(T));
  out.append(raw, sizeof(T));
}

std::string binarySquarePly(bool bigEndian) {
  std::string s = std::string("ply\nformat ") + (bigEndian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 4\nproperty float32 x\nproperty float32 y\nproperty float32 z\n"
                  "property double nx\nproperty double ny\nproperty double nz\n"
                  "property uint8 red\nproperty uint8 green\nproperty uint8 blue\n"
                  "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                  "element face 1\nproperty uchar flags\nproperty list uchar uint vertex_index\n"
                  "property list ushort float texcoord\nend_header\n";
  for (const PlyVertex& v : kSquare) {
    putBinary(s, v.x, bigEndian);
    putBinary(s, v.y, bigEndian);
    putBinary(s, v.z, bigEndian);
    putBinary<double>(s, v.nx, bigEndian);
    putBinary<double>(s, v.ny, bigEndian);
    putBinary<double>(s, v.nz, bigEndian);
    putBinary(s, v.r, bigEndian);
    putBinary(s, v.g, bigEndian);
    putBinary(s, v.b, bigEndian);
  }
  putBinary<std::int32_t>(s, 0, bigEndian);
  putBinary<std::int32_t>(s, 1, bigEndian);
  putBinary<std::uint8_t>(s, 7, bigEndian);
  putBinary<std::uint8_t>(s, 4, bigEndian);
  for (std::uint32_t i : {0u, 1u, 2u, 3u}) putBinary(s, i, bigEndian);
  putBinary<std::uint16_t>(s, 2, bigEndian);
  putBinary(s, 0.5f, bigEndian);
  putBinary(s, 0.5f, bigEndian);
  return s;
}

void expectSquare(const Mesh& m) {
  ASSERT_EQ(m.positions.size(), 4u);
  ASSERT_EQ(m.triangles.size(), 2u);  // the quad, fan-triangulated
  EXPECT_EQ(m.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(m.triangles[1], glm::uvec3(0, 2, 3));
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(m.positions[i], glm::vec3(kSquare[i].x, kSquare[i].y, kSquare[i].z)) << i;
  }
  expectUnitNormals(m);
  for (const glm::vec3& n : m.normals) EXPECT_NEAR(n.y, 1.0f, 1e-6f);
  EXPECT_NEAR(totalArea(m), 1.0, 1e-6);
}

TEST(PlyLoader, AsciiQuadWithNormalsAndExtraProperties) {
  TempDir dir(tempPrefix());
  const Mesh m = loadMesh(writeFile(dir / "square.ply", asciiSquarePly()));
  EXPECT_EQ(m.name, "square");
  expectSquare(m);
}

TEST(PlyLoader, AsciiWithCrlfLineEnds) {
  TempDir dir(tempPrefix());
  expectSquare(loadMesh(writeFile(dir / "square-crlf.PLY", asciiSquarePly("\r\n"))));
}

TEST(PlyLoader, BinaryLittleAndBigEndianReadTheSameAsAscii) {
  TempDir dir(tempPrefix());
  const Mesh ascii = loadMesh(writeFile(dir / "a.ply", asciiSquarePly()));
  for (const bool big : {false, true}) {
    SCOPED_TRACE(big ? "big-endian" : "little-endian");
    const Mesh m = loadMesh(writeFile(dir / (big ? "be.ply" : "le.ply"), binarySquarePly(big)));
    expectSquare(m);
    EXPECT_EQ(m.positions, ascii.positions);
    EXPECT_EQ(m.triangles, ascii.triangles);
  }
}

TEST(PlyLoader, WithoutNormalsComputesThemFromTheFaces) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n0 0 1\n1 0 0\n3 0 1 2\n";
  const Mesh m = parsePly(ply, "tri");
  ASSERT_EQ(m.triangles.size(), 1u);
  expectUnitNormals(m);
  // (0,0,1) − (0,0,0) × (1,0,0) − (0,0,0) = +Y: the face's winding decides.
  for (const glm::vec3& n : m.normals) EXPECT_NEAR(n.y, 1.0f, 1e-6f);
}

TEST(PlyLoader, PentagonIsFanTriangulated) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "1 0 0\n0.309 0 0.951\n-0.809 0 0.588\n-0.809 0 -0.588\n0.309 0 -0.951\n5 0 1 2 3 4\n";
  const Mesh m = parsePly(ply, "pentagon");
  ASSERT_EQ(m.triangles.size(), 3u);
  EXPECT_EQ(m.triangles[2], glm::uvec3(0, 3, 4));
}

TEST(PlyLoader, RefusesCorruptFiles) {
  TempDir dir(tempPrefix());
  const std::string good = binarySquarePly(false);
  struct Case {
    std::string label, bytes, expect;
  };
  std::string badIndex = asciiSquarePly();
  badIndex.replace(badIndex.find("4 0 1 2 3"), 9, "4 0 1 2 9");
  std::string negativeIndex = asciiSquarePly();
  negativeIndex.replace(negativeIndex.find("4 0 1 2 3"), 9, "4 0 1 -2 3");
  std::string absurd = asciiSquarePly();
  absurd.replace(absurd.find("element vertex 4"), 16, "element vertex 60000000");
  std::string hugeBinary = good;
  hugeBinary.replace(hugeBinary.find("element vertex 4"), 16, "element vertex 4000000");
  std::string badType = asciiSquarePly();
  badType.replace(badType.find("property float x"), 16, "property float128 x");
  std::string twoCorners = asciiSquarePly();
  twoCorners.replace(twoCorners.find("4 0 1 2 3 2"), 11, "2 0 1 2");
  std::string badToken = asciiSquarePly();
  badToken.replace(badToken.find("0.000000"), 8, "zero");
  const std::vector<Case> cases = {
      {"truncated binary", good.substr(0, good.size() - 5), "truncated"},
      {"truncated ascii", asciiSquarePly().substr(0, asciiSquarePly().size() - 12), "truncated"},
      {"binary body cut inside the vertices", good.substr(0, good.find("end_header\n") + 20), "truncated"},
      {"count larger than the file", hugeBinary, "truncated"},
      {"index out of range", badIndex, "out of range"},
      {"negative index", negativeIndex, "out of range"},
      {"absurd count", absurd, "absurd"},
      {"no end_header", "ply\nformat ascii 1.0\nelement vertex 0\n", "end_header"},
      {"not PLY", "solid cube\nfacet normal 0 0 1\n", "unknown format"},
      {"unknown encoding", "ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown PLY format"},
      {"unknown type", badType, "unknown property type"},
      {"degenerate polygon", twoCorners, "corners"},
      {"bad ascii number", badToken, "bad vertex value"},
      {"no faces", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                   "property float z\nend_header\n0 0 0\n",
       "no face element"},
      {"empty file", "", "end_header"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    const std::string path = writeFile(dir / "bad.ply", c.bytes);
    expectError([&] { loadMesh(path); }, {path, c.expect});
  }
}

// ------------------------------------------------------------ OBJ

TEST(ObjLoader, WithoutNormalsKeepsTheFileNumberingAndComputesNormals) {
  TempDir dir(tempPrefix());
  // A tetrahedron with outward winding, one face written as a quad-free
  // triangle list, plus a comment, a group and a material reference that
  // must not be opened.
  const std::string path = writeFile(dir / "tet.obj",
                                     "# tetrahedron\nmtllib missing.mtl\no tet\n"
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  const Mesh m = loadMesh(path);
  EXPECT_EQ(m.name, "tet");
  ASSERT_EQ(m.positions.size(), 4u);
  ASSERT_EQ(m.triangles.size(), 4u);
  EXPECT_EQ(m.positions[3], glm::vec3(0, 0, 1));
  EXPECT_EQ(m.triangles[0], glm::uvec3(0, 2, 1));
  expectUnitNormals(m);
  // Vertex 0 sits at the corner: its normal points away from the body, along −(1,1,1).
  EXPECT_LT(glm::dot(glm::dvec3(m.normals[0]), glm::dvec3(1, 1, 1)), 0.0);
}

TEST(ObjLoader, QuadsAreTriangulated) {
  const Mesh m = parseObj("v 0 0 0\nv 0 0 1\nv 1 0 1\nv 1 0 0\nf 1 2 3 4\n", "quad");
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_NEAR(totalArea(m), 1.0, 1e-6);
  for (const glm::vec3& n : m.normals) EXPECT_NEAR(n.y, 1.0f, 1e-6f);
}

TEST(ObjLoader, NormalsMakeUniquePositionNormalVertices) {
  // A unit cube with one normal per face (v//vn): each corner is shared by
  // three faces with three normals, so 8 positions become 24 vertices.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n"
      "vt 0 0\n"
      "f 1//1 4//1 3//1 2//1\nf 5//2 6//2 7//2 8//2\nf 1//3 2//3 6//3 5//3\n"
      "f 4/1/4 8/1/4 7/1/4 3/1/4\nf 1//5 5//5 8//5 4//5\nf 2//6 3//6 7//6 6//6\n";
  const Mesh m = parseObj(obj, "cube");
  ASSERT_EQ(m.positions.size(), 24u);
  ASSERT_EQ(m.triangles.size(), 12u);
  expectUnitNormals(m);
  EXPECT_NEAR(totalArea(m), 6.0, 1e-6);
  // Every triangle's vertices carry the file's normal of its face, and the
  // winding agrees with it.
  for (const glm::uvec3& t : m.triangles) {
    const glm::dvec3 n(m.normals[t.x]);
    EXPECT_EQ(m.normals[t.x], m.normals[t.y]);
    EXPECT_EQ(m.normals[t.x], m.normals[t.z]);
    const glm::dvec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
    EXPECT_GT(glm::dot(glm::cross(b - a, c - a), n), 0.0);
    EXPECT_NEAR(glm::dot(a, n), glm::dot(glm::dvec3(0.5), n) + 0.5, 1e-6);  // on its face
  }
}

TEST(ObjLoader, MixedNormalsFallBackToComputedOnes) {
  const Mesh m = parseObj("v 0 0 0\nv 0 0 1\nv 1 0 1\nv 1 0 0\nvn 1 0 0\nf 1//1 2//1 3//1\nf 1 3 4\n", "mixed");
  ASSERT_EQ(m.positions.size(), 4u);
  for (const glm::vec3& n : m.normals) EXPECT_NEAR(n.y, 1.0f, 1e-6f);
}

TEST(ObjLoader, NegativeIndicesAreRelative) {
  const Mesh m = parseObj("v 0 0 0\nv 0 0 1\nv 1 0 1\nf -3 -2 -1\n", "relative");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0], glm::uvec3(0, 1, 2));
}

TEST(ObjLoader, RefusesCorruptFiles) {
  TempDir dir(tempPrefix());
  struct Case {
    std::string label, text, expect;
  };
  const std::vector<Case> cases = {
      {"vertex index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "out of range"},
      {"quad index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 9\n", "out of range"},
      {"normal index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//4\n", "out of range"},
      {"zero index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "not a valid OBJ"},
      {"no faces", "v 0 0 0\nv 1 0 0\n", "no triangles"},
      {"empty", "", "no triangles"},
      {"non-finite vertex", "v 0 0 1e999\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "non-finite"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    const std::string path = writeFile(dir / "bad.obj", c.text);
    expectError([&] { loadMesh(path); }, {path, c.expect});
  }
}

// Fraction of vertex normals pointing away from the mesh's centre of
// bounds: ~1 for a star-shaped closed mesh whose normals point outward.
double outwardFraction(const Mesh& m) {
  const glm::dvec3 c = m.bounds().centre();
  std::size_t out = 0;
  for (std::size_t i = 0; i < m.normals.size(); ++i) {
    if (glm::dot(glm::dvec3(m.normals[i]), glm::dvec3(m.positions[i]) - c) > 0.0) ++out;
  }
  return static_cast<double>(out) / static_cast<double>(m.normals.size());
}

TEST(MeshLoader, InwardWoundClosedMeshesAreTurnedOutward) {
  // A tetrahedron around the origin, every face wound inward, no normals.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "1 1 1\n-1 -1 1\n-1 1 -1\n1 -1 -1\n3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n";
  Mesh inward = parsePly(ply, "tetra");
  EXPECT_EQ(outwardFraction(inward), 1.0);
  // The same faces wound the other way read the same: outward.
  std::string outward = ply;
  for (const auto& [from, to] : {std::pair{"3 0 1 2", "3 0 2 1"}, std::pair{"3 0 3 1", "3 0 1 3"},
                                 std::pair{"3 0 2 3", "3 0 3 2"}, std::pair{"3 1 3 2", "3 1 2 3"}}) {
    outward.replace(outward.find(from), std::string(from).size(), to);
  }
  EXPECT_EQ(outwardFraction(parsePly(outward, "tetra")), 1.0);
}

TEST(MeshLoader, RefusesUnknownExtensionsAndMissingFiles) {
  TempDir dir(tempPrefix());
  const std::string stl = writeFile(dir / "model.stl", "solid x\n");
  expectError([&] { loadMesh(stl); }, {stl, "unknown mesh format", ".stl"});
  const std::string missing = (fs::temp_directory_path() / "haarcast-no-such-mesh.obj").string();
  expectError([&] { loadMesh(missing); }, {missing, "cannot open"});
}

// ------------------------------------------------------------ real models

#ifdef HAARCAST_SHARED_DATA
const fs::path kMeshes = fs::path(HAARCAST_SHARED_DATA) / "meshes";
#else
const fs::path kMeshes;
#endif

#define REQUIRE_SHARED_MESHES()                                                   \
  if (kMeshes.empty() || !fs::is_directory(kMeshes)) {                            \
    GTEST_SKIP() << "../shared/data/meshes is not here (see shared/data/SOURCES.md)"; \
  }

Mesh timedLoad(const std::string& file) {
  const auto start = std::chrono::steady_clock::now();
  Mesh m = loadMesh((kMeshes / file).string());
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << "[ timing   ] loadMesh(" << file << "): " << ms << " ms, " << m.positions.size() << " vertices, "
            << m.triangles.size() << " triangles\n";
  ::testing::Test::RecordProperty(file + "_load_ms", std::to_string(ms));
  return m;
}

// Fraction of vertex normals that agree (cos > 0.5) with the area-weighted
// face normals of the same mesh: ~1 when the file's normals and winding agree.
double normalAgreement(const Mesh& m) {
  Mesh faces = m;
  faces.computeNormals();
  std::size_t agree = 0;
  for (std::size_t i = 0; i < m.normals.size(); ++i) {
    if (glm::dot(glm::dvec3(m.normals[i]), glm::dvec3(faces.normals[i])) > 0.5) ++agree;
  }
  return static_cast<double>(agree) / static_cast<double>(m.normals.size());
}

TEST(MeshLoaderSharedData, BunnyAsciiPly) {
  REQUIRE_SHARED_MESHES();
  const Mesh m = timedLoad("bunny.ply");
  EXPECT_EQ(m.name, "bunny");
  EXPECT_EQ(m.positions.size(), 35947u);
  EXPECT_EQ(m.triangles.size(), 69451u);
  expectUnitNormals(m);
  // bunny.ply is wound inward; the loader turns it outward.
  EXPECT_GT(outwardFraction(m), 0.8);
  // The Stanford bunny is about 0.16 units across (metres).
  EXPECT_NEAR(m.bounds().radius(), 0.13, 0.03);
}

TEST(MeshLoaderSharedData, LucyBinaryPly) {
  REQUIRE_SHARED_MESHES();
  const Mesh m = timedLoad("lucy.ply");
  EXPECT_EQ(m.positions.size(), 49987u);
  EXPECT_EQ(m.triangles.size(), 99970u);
  expectUnitNormals(m);
}

TEST(MeshLoaderSharedData, MoaiObjWithNormals) {
  REQUIRE_SHARED_MESHES();
  const Mesh m = timedLoad("moai.obj");
  EXPECT_EQ(m.name, "moai");
  // 6,020 positions and 6,020 normals, paired one to one in the file.
  EXPECT_GE(m.positions.size(), 6020u);
  EXPECT_LE(m.positions.size(), 3 * m.triangles.size());
  expectUnitNormals(m);
  EXPECT_GT(normalAgreement(m), 0.95);
}

TEST(MeshLoaderSharedData, ObjAndPlyBunniesAgree) {
  REQUIRE_SHARED_MESHES();
  const Mesh ply = loadMesh((kMeshes / "bunny.ply").string());
  const Mesh obj = timedLoad("stanford-bunny.obj");
  EXPECT_EQ(obj.positions.size(), ply.positions.size());
  EXPECT_NEAR(obj.bounds().radius(), ply.bounds().radius(), 1e-3 * ply.bounds().radius());
}

TEST(MeshLoaderSharedData, EveryModelLoads) {
  REQUIRE_SHARED_MESHES();
  for (const char* file : {"cat-low-resolution.obj", "spot.obj", "teapot.obj", "venus.obj"}) {
    SCOPED_TRACE(file);
    const Mesh m = timedLoad(file);
    EXPECT_GT(m.triangles.size(), 100u);
    expectUnitNormals(m);
    EXPECT_NO_THROW(m.validate());
  }
}

}  // namespace
}  // namespace haarcast::io
