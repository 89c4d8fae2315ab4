// Tests of the PLY reader: formats, property types and synonyms, skipped data, malformed input
// and every PLY file of the shared scenes.
#include "parser/ply.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "shared_data.h"

namespace rlpbrt {
namespace {

namespace fs = std::filesystem;

// Builds a binary PLY body with a given byte order.
struct Bytes {
    bool bigEndian = false;
    std::string s;
    template <typename T>
    Bytes& put(T v) {
        unsigned char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        uint16_t one = 1;
        bool hostLittle = *reinterpret_cast<unsigned char*>(&one) == 1;
        if (bigEndian == hostLittle)
            for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
        s.append(reinterpret_cast<char*>(b), sizeof(T));
        return *this;
    }
};

bool readString(const std::string& text, PlyMesh* mesh, std::string* error) {
    return readPlyFromMemory(text.data(), text.size(), mesh, error);
}

std::string dataDir() { return std::string(RLPBRT_SOURCE_DIR) + "/tests/data/ply"; }

const char* kTriHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(Ply, AsciiTriangle) {
    PlyMesh m;
    std::string err;
    ASSERT_TRUE(readString(std::string(kTriHeader) + "0 0 0\n1 0 0\n0 1.5 -2e1\n3 0 1 2\n", &m,
                           &err))
        << err;
    ASSERT_EQ(m.positions.size(), 9u);
    EXPECT_FLOAT_EQ(m.positions[7], 1.5f);
    EXPECT_FLOAT_EQ(m.positions[8], -20.f);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_TRUE(m.normals.empty());
    EXPECT_TRUE(m.uvs.empty());
    EXPECT_EQ(m.quadCount, 0u);
}

TEST(Ply, AsciiQuadCubeWithExtraElementsAndSt) {
    PlyMesh m;
    std::string err;
    ASSERT_TRUE(readPly(dataDir() + "/cube_quads_ascii.ply", &m, &err)) << err;
    EXPECT_EQ(m.vertexCount(), 8u);
    EXPECT_EQ(m.triangleCount(), 12u);
    EXPECT_EQ(m.quadCount, 6u);
    EXPECT_EQ(m.polygonCount, 0u);
    ASSERT_EQ(m.uvs.size(), 16u);
    EXPECT_FLOAT_EQ(m.uvs[2 * 2 + 0], 1.f);
    EXPECT_FLOAT_EQ(m.uvs[2 * 3 + 1], 1.f);
    // First quad 0 3 2 1 -> (0,3,2), (0,2,1).
    EXPECT_EQ(std::vector<uint32_t>(m.indices.begin(), m.indices.begin() + 6),
              (std::vector<uint32_t>{0, 3, 2, 0, 2, 1}));
    EXPECT_FLOAT_EQ(m.positions[3 * 6 + 2], 1.f);
}

TEST(Ply, BigEndianPentagonDoubleCoordinates) {
    PlyMesh m;
    std::string err;
    ASSERT_TRUE(readPly(dataDir() + "/pentagon_be.ply", &m, &err)) << err;
    EXPECT_EQ(m.vertexCount(), 6u);
    EXPECT_EQ(m.triangleCount(), 4u);  // pentagon fanned into 3 + one triangle
    EXPECT_EQ(m.polygonCount, 1u);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 1, 5}));
    EXPECT_NEAR(m.positions[3 * 1 + 0], std::cos(2 * 3.14159265 / 5), 1e-6);
    ASSERT_EQ(m.normals.size(), 18u);
    EXPECT_FLOAT_EQ(m.normals[2], 1.f);
    ASSERT_EQ(m.uvs.size(), 12u);
    EXPECT_FLOAT_EQ(m.uvs[2 * 3 + 0], 0.3f);
    EXPECT_FLOAT_EQ(m.uvs[2 * 3 + 1], 0.7f);
}

// A binary file exercising every scalar type, uv under u/v, normals, an unknown list in the
// vertex element, an unknown element with lists, and uint list counts.
std::string allTypesFile(bool bigEndian) {
    std::string h = std::string("ply\nformat ") +
                    (bigEndian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\ncomment all types\n"
                    "element vertex 4\n"
                    "property int8 a\nproperty float x\nproperty double y\nproperty short z\n"
                    "property list uint8 float junk\n"
                    "property float nx\nproperty float ny\nproperty float nz\n"
                    "property uchar b\nproperty float32 u\nproperty float64 v\n"
                    "property ushort c\nproperty uint d\nproperty int16 e\nproperty uint16 f\n"
                    "element edge 2\nproperty int32 v1\nproperty list uint32 int16 more\n"
                    "element face 2\nproperty uint8 flags\n"
                    "property list uint int vertex_indices\nproperty list char uchar extra\n"
                    "end_header\n";
    Bytes b;
    b.bigEndian = bigEndian;
    for (int i = 0; i < 4; ++i) {
        b.put<int8_t>(-3).put<float>(float(i)).put<double>(10.0 + i).put<int16_t>(int16_t(-i));
        b.put<uint8_t>(uint8_t(i));  // junk list of i floats
        for (int k = 0; k < i; ++k) b.put<float>(99.f);
        b.put<float>(0.f).put<float>(1.f).put<float>(0.f);
        b.put<uint8_t>(200).put<float>(0.25f * i).put<double>(1.0 - 0.25 * i);
        b.put<uint16_t>(7).put<uint32_t>(8).put<int16_t>(-9).put<uint16_t>(10);
    }
    for (int i = 0; i < 2; ++i) {
        b.put<int32_t>(i).put<uint32_t>(3);
        for (int k = 0; k < 3; ++k) b.put<int16_t>(int16_t(k));
    }
    b.put<uint8_t>(1).put<uint32_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
    b.put<int8_t>(2).put<uint8_t>(5).put<uint8_t>(6);
    b.put<uint8_t>(1).put<uint32_t>(4).put<int32_t>(0).put<int32_t>(2).put<int32_t>(3);
    b.put<int32_t>(1).put<int8_t>(0);
    return h + b.s;
}

TEST(Ply, BinaryAllScalarTypesBothEndians) {
    for (bool be : {false, true}) {
        PlyMesh m;
        std::string err;
        ASSERT_TRUE(readString(allTypesFile(be), &m, &err)) << err;
        ASSERT_EQ(m.vertexCount(), 4u);
        for (int i = 0; i < 4; ++i) {
            EXPECT_FLOAT_EQ(m.positions[3 * i + 0], float(i));
            EXPECT_FLOAT_EQ(m.positions[3 * i + 1], 10.f + i);
            EXPECT_FLOAT_EQ(m.positions[3 * i + 2], float(-i));
            EXPECT_FLOAT_EQ(m.normals[3 * i + 1], 1.f);
            EXPECT_FLOAT_EQ(m.uvs[2 * i + 0], 0.25f * i);
            EXPECT_FLOAT_EQ(m.uvs[2 * i + 1], 1.f - 0.25f * i);
        }
        EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 1}));
        EXPECT_EQ(m.quadCount, 1u);
    }
}

TEST(Ply, ListTypesUcharUintAndVertexIndexSynonym) {
    for (const char* listDecl :
         {"uchar uint vertex_indices", "uint8 uint32 vertex_index", "ushort short vertex_indices",
          "int int vertex_indices", "char uchar vertex_indices"}) {
        std::string type = std::string(listDecl);
        std::string countT = type.substr(0, type.find(' '));
        std::string rest = type.substr(type.find(' ') + 1);
        std::string idxT = rest.substr(0, rest.find(' '));
        std::string h = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                        "property float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list " + type + "\nend_header\n";
        Bytes b;
        for (int i = 0; i < 9; ++i) b.put<float>(float(i));
        auto putInt = [&](const std::string& t, int v) {
            if (t == "uchar" || t == "uint8" || t == "char") b.put<uint8_t>(uint8_t(v));
            else if (t == "ushort" || t == "short") b.put<uint16_t>(uint16_t(v));
            else b.put<uint32_t>(uint32_t(v));
        };
        putInt(countT, 3);
        putInt(idxT, 2);
        putInt(idxT, 1);
        putInt(idxT, 0);
        PlyMesh m;
        std::string err;
        ASSERT_TRUE(readString(h + b.s, &m, &err)) << listDecl << ": " << err;
        EXPECT_EQ(m.indices, (std::vector<uint32_t>{2, 1, 0})) << listDecl;
    }
}

TEST(Ply, UvSynonymsAndPartialNormalsIgnored) {
    for (const char* uv : {"u v", "s t", "texture_u texture_v", "texture_s texture_t"}) {
        std::string n = uv;
        std::string un = n.substr(0, n.find(' ')), vn = n.substr(n.find(' ') + 1);
        std::string text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                           "property float y\nproperty float z\nproperty float nx\n"
                           "property float " + un + "\nproperty float " + vn +
                           "\nelement face 1\nproperty list uchar int vertex_indices\n"
                           "end_header\n0 0 0 1 0.5 0.75\n1 0 0 1 0 0\n0 1 0 1 0 0\n3 0 1 2\n";
        PlyMesh m;
        std::string err;
        ASSERT_TRUE(readString(text, &m, &err)) << uv << ": " << err;
        ASSERT_EQ(m.uvs.size(), 6u) << uv;
        EXPECT_FLOAT_EQ(m.uvs[0], 0.5f);
        EXPECT_FLOAT_EQ(m.uvs[1], 0.75f);
        EXPECT_TRUE(m.normals.empty());  // only nx present
    }
}

TEST(Ply, CrLfHeaderAndEmptyUnknownElement) {
    std::string text = "ply\r\nformat ascii 1.0\r\ncomment x\r\nelement vertex 3\r\n"
                       "property float x\r\nproperty float y\r\nproperty float z\r\n"
                       "element nothing 1000000000000\r\n"
                       "element face 1\r\nproperty list uchar int vertex_indices\r\n"
                       "end_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2";
    PlyMesh m;
    std::string err;
    ASSERT_TRUE(readString(text, &m, &err)) << err;
    EXPECT_EQ(m.triangleCount(), 1u);
}

struct BadCase {
    const char* name;
    std::string text;
    const char* expect;  // substring of the error message
};

std::vector<BadCase> badCases() {
    std::string tri = kTriHeader;
    const std::string leHead =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n";
    Bytes okVerts;
    for (int i = 0; i < 9; ++i) okVerts.put<float>(float(i % 2));
    Bytes hugeList = okVerts;
    std::string hugeListHead = leHead;
    hugeListHead.replace(hugeListHead.find("uchar int"), 9, "uint int");
    hugeList.put<uint32_t>(0xffffffffu).put<int32_t>(0);
    Bytes badIdx = okVerts;
    badIdx.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(3);
    Bytes negIdx = okVerts;
    negIdx.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(-1).put<int32_t>(2);
    Bytes nanVerts;
    for (int i = 0; i < 9; ++i) nanVerts.put<float>(i == 4 ? NAN : 0.f);
    nanVerts.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2);
    std::string hugeToken(100000, '7');
    return {
        {"empty", "", "not a PLY file"},
        {"not ply", "plx\nformat ascii 1.0\nend_header\n", "not a PLY file"},
        {"no end_header", "ply\nformat ascii 1.0\nelement vertex 3\n", "end_header"},
        {"no format", "ply\nelement vertex 0\nend_header\n", "format"},
        {"bad format", "ply\nformat binary_middle_endian 1.0\nend_header\n", "format"},
        {"bad version", "ply\nformat ascii 2.0\nend_header\n", "version"},
        {"unknown type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n"
                         "end_header\n", "unknown property type"},
        {"property first", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
         "before any 'element'"},
        {"bad count", "ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", "element"},
        {"float list count", "ply\nformat ascii 1.0\nelement vertex 1\n"
                             "property list float int vertex_indices\nend_header\n",
         "integer type"},
        {"unknown keyword", "ply\nformat ascii 1.0\nelephant 3\nend_header\n", "keyword"},
        {"absurd vertex count",
         "ply\nformat binary_little_endian 1.0\nelement vertex 999999999999999\n"
         "property float x\nproperty float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n\x01\x02",
         "declares"},
        {"count overflow", "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\n"
                           "end_header\n", "element"},
        {"truncated ascii", tri + "0 0 0\n1 0 0\n0 1 0\n3 0 1", "end of file"},
        {"truncated binary", leHead + okVerts.s.substr(0, 20), "declares"},
        {"truncated binary faces", leHead + okVerts.s + std::string("\x03\x00\x00", 3),
         "longer than"},
        {"huge list count", hugeListHead + hugeList.s, "longer than"},
        {"index out of range", leHead + badIdx.s, "out of range"},
        {"negative index", leHead + negIdx.s, "out of range"},
        {"two vertex face", tri + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "at least 3"},
        {"nan coordinate ascii", tri + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "non-finite"},
        {"inf coordinate ascii", tri + "0 0 0\n1 1e999 0\n0 1 0\n3 0 1 2\n", "non-finite"},
        {"nan coordinate binary", leHead + nanVerts.s, "non-finite"},
        {"garbage number", tri + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "invalid number"},
        {"huge token", tri + "0 0 0\n1 0 0\n0 1 0\n3 0 1 " + hugeToken + "\n", "invalid integer"},
        {"missing xyz", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        "0\n3 0 0 0\n", "x, y, z"},
        {"no faces", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                     "property float y\nproperty float z\nend_header\n0 0 0\n", "no faces"},
        {"no index list", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                          "property float y\nproperty float z\nelement face 1\n"
                          "property list uchar int idx\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                          "3 0 1 2\n", "vertex_indices"},
        {"duplicate element", "ply\nformat ascii 1.0\nelement vertex 0\nelement vertex 0\n"
                              "end_header\n", "duplicate"},
    };
}

TEST(Ply, MalformedInputsFailWithMessage) {
    for (const BadCase& c : badCases()) {
        PlyMesh m;
        std::string err;
        EXPECT_FALSE(readString(c.text, &m, &err)) << c.name;
        EXPECT_NE(err.find(c.expect), std::string::npos)
            << c.name << ": message '" << err << "' lacks '" << c.expect << "'";
        EXPECT_TRUE(m.positions.empty() && m.indices.empty()) << c.name;
    }
}

TEST(Ply, ErrorsNameLineOrByteOffset) {
    PlyMesh m;
    std::string err;
    EXPECT_FALSE(readString(std::string(kTriHeader) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", &m,
                            &err));
    EXPECT_NE(err.find("PLY line 13"), std::string::npos) << err;
    const std::string leHead =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n";
    Bytes b;
    for (int i = 0; i < 9; ++i) b.put<float>(0.f);
    b.put<uint8_t>(3).put<int32_t>(0).put<int32_t>(7).put<int32_t>(1);
    EXPECT_FALSE(readString(leHead + b.s, &m, &err));
    // The bad face starts after the header and 36 bytes of vertices.
    std::string expect = "byte offset " + std::to_string(leHead.size() + 36);
    EXPECT_NE(err.find(expect), std::string::npos) << err << " vs " << expect;
}

TEST(Ply, MissingFileFails) {
    PlyMesh m;
    std::string err;
    EXPECT_FALSE(readPly(dataDir() + "/does_not_exist.ply", &m, &err));
    EXPECT_NE(err.find("cannot open"), std::string::npos);
}

// Every truncation of a valid binary file fails cleanly (never crashes).
TEST(Ply, EveryTruncationFails) {
    std::string full = allTypesFile(false);
    for (size_t n = 0; n < full.size(); ++n) {
        PlyMesh m;
        std::string err;
        EXPECT_FALSE(readString(full.substr(0, n), &m, &err)) << n;
        EXPECT_FALSE(err.empty()) << n;
    }
}

TEST(Ply, AllScenePlyFilesRead) {
    RLPBRT_REQUIRE_SHARED();
    fs::path dir = fs::path(rlpbrt::test::sharedDir()) / "scenes";
    int files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        if (!entry.is_regular_file() || entry.path().extension() != ".ply") continue;
        ++files;
        PlyMesh m;
        std::string err;
        ASSERT_TRUE(readPly(entry.path().string(), &m, &err)) << entry.path() << ": " << err;
        EXPECT_GT(m.vertexCount(), 0u) << entry.path();
        EXPECT_GT(m.triangleCount(), 0u) << entry.path();
        EXPECT_EQ(m.indices.size() % 3, 0u);
        uint32_t maxIdx = 0;
        for (uint32_t i : m.indices) maxIdx = std::max(maxIdx, i);
        EXPECT_LT(maxIdx, m.vertexCount()) << entry.path();
        EXPECT_TRUE(m.normals.empty() || m.normals.size() == m.positions.size());
        EXPECT_TRUE(m.uvs.empty() || m.uvs.size() == 2 * m.vertexCount());
    }
    EXPECT_GT(files, 0);
}

}  // namespace
}  // namespace rlpbrt
