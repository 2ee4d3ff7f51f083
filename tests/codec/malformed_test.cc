// Malformed containers: every truncation, random byte flips, the same behind
// a recomputed integrity hash (what a crafted file looks like), and
// hand-built sections with bad counts, lengths, ids and lattices. The decoder
// must return INVALID_ARGUMENT (or, behind a valid hash, possibly a valid
// mesh) and never crash or over-allocate — this suite runs under ASan/UBSan.
#include <random>
#include <utility>
#include <vector>

#include "core/codec/byte_io.h"
#include "core/codec/container.h"
#include "core/codec/draco_columns.h"
#include "core/util/sha256.h"
#include "gtest/gtest.h"
#include "tests/codec/grid_mesh.h"

namespace svrc::codec {
namespace {

constexpr size_t kHashSectionSize = 12 + 32;

mesh::TetMesh SmallMesh() {
  testing::GridMeshOptions o;
  o.nx = 2;
  o.ny = 1;
  o.nz = 1;
  o.jitter = 0.1;
  o.hilbert_order = true;
  return testing::MakeGridMesh(o);
}

std::string Encode(const mesh::TetMesh& m, int bits = 0) {
  EncodeOptions o;
  o.position_quantization_bits = bits;
  absl::StatusOr<std::string> bytes = EncodeTetMesh(m, o);
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  return bytes.ok() ? *bytes : std::string();
}

// Appends the HASH section a real encoder would write.
std::string Seal(const std::string& body) {
  const util::Sha256::Digest d = util::Sha256Digest(body);
  ByteWriter w;
  w.Bytes(body);
  w.Bytes("HASH");
  w.U64(32);
  w.Bytes(std::string_view(reinterpret_cast<const char*>(d.data()), d.size()));
  return std::move(w.str());
}

struct Parts {
  std::string header;                                     // magic, version, flags
  std::vector<std::pair<std::string, std::string>> sections;  // tag, payload (no HASH)
};

Parts Split(const std::string& bytes) {
  Parts p;
  p.header = bytes.substr(0, 8);
  std::vector<Section> sections;
  EXPECT_TRUE(SplitSections(
      std::string_view(bytes).substr(8, bytes.size() - 8 - kHashSectionSize), &sections));
  for (const Section& s : sections) p.sections.emplace_back(s.tag, s.payload);
  return p;
}

std::string Join(const Parts& p) {
  ByteWriter w;
  w.Bytes(p.header);
  for (const auto& [tag, payload] : p.sections) {
    w.Bytes(tag);
    w.U64(payload.size());
    w.Bytes(payload);
  }
  return Seal(w.str());
}

std::string& SectionPayload(Parts& p, std::string_view tag) {
  for (auto& [t, payload] : p.sections) {
    if (t == tag) return payload;
  }
  ADD_FAILURE() << "no section " << tag;
  static std::string none;
  return none;
}

void ExpectInvalid(const std::string& bytes, const std::string& why = "") {
  const absl::StatusOr<mesh::TetMesh> m = DecodeTetMesh(bytes);
  EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument) << why << ": " << m.status();
}

// A decoded mesh must at least be internally consistent.
void ExpectInvalidOrConsistent(const std::string& bytes) {
  const absl::StatusOr<mesh::TetMesh> m = DecodeTetMesh(bytes);
  if (!m.ok()) {
    EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument) << m.status();
    return;
  }
  const size_t n = m->positions.size();
  EXPECT_LE(m->num_input_vertices, n);
  for (const auto& t : m->tets) {
    for (uint32_t v : t) ASSERT_LT(v, n);
  }
  for (const auto& t : m->triangles) {
    for (uint32_t v : t) ASSERT_LT(v, n);
  }
  EXPECT_TRUE(m->tet_region.empty() || m->tet_region.size() == m->tets.size());
  EXPECT_TRUE(m->triangle_marker.empty() || m->triangle_marker.size() == m->triangles.size());
}

TEST(MalformedTest, SplitJoinIsIdentity) {
  // The helpers below rebuild containers; make sure they rebuild them exactly.
  const std::string bytes = Encode(SmallMesh());
  const Parts p = Split(bytes);
  ASSERT_EQ(p.sections.size(), 5u);
  EXPECT_EQ(Join(p), bytes);
  EXPECT_TRUE(DecodeTetMesh(Join(p)).ok());
}

TEST(MalformedTest, EveryTruncationFails) {
  for (int bits : {0, 20}) {
    const std::string bytes = Encode(SmallMesh(), bits);
    for (size_t len = 0; len < bytes.size(); ++len) {
      ExpectInvalid(bytes.substr(0, len), "truncated to " + std::to_string(len));
    }
    ExpectInvalid(bytes + '\0', "one byte appended");
  }
}

TEST(MalformedTest, RandomByteFlipsFail) {
  const std::string bytes = Encode(SmallMesh());
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string b = bytes;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int f = 0; f < flips; ++f) b[rng() % b.size()] ^= static_cast<char>(1 + rng() % 255);
    ExpectInvalid(b, "trial " + std::to_string(trial));
  }
}

TEST(MalformedTest, CraftedFlipsBehindAValidHash) {
  // Flip bytes of the body and recompute the hash: now the section parser,
  // the Draco decoder and the id checks are what stands between the bytes
  // and a crash.
  for (int bits : {0, 12, 20}) {
    const std::string bytes = Encode(SmallMesh(), bits);
    const std::string body = bytes.substr(0, bytes.size() - kHashSectionSize);
    std::mt19937_64 rng(11 + bits);
    for (int trial = 0; trial < 1500; ++trial) {
      std::string b = body;
      const int flips = 1 + static_cast<int>(rng() % 3);
      // Mostly past the 8-byte header (header flips are rejected up front).
      for (int f = 0; f < flips; ++f) {
        b[8 + rng() % (b.size() - 8)] ^= static_cast<char>(1 + rng() % 255);
      }
      ExpectInvalidOrConsistent(Seal(b));
    }
    for (size_t len = 8; len < body.size(); ++len) ExpectInvalid(Seal(body.substr(0, len)));
  }
}

TEST(MalformedTest, HeaderChecks) {
  const std::string bytes = Encode(SmallMesh());
  std::string b = bytes;
  b[0] = 'X';
  ExpectInvalid(Seal(b.substr(0, b.size() - kHashSectionSize)), "magic");
  b = bytes;
  b[4] = 2;  // format version 2
  ExpectInvalid(Seal(b.substr(0, b.size() - kHashSectionSize)), "version");
  b = bytes;
  b[6] |= 0x10;  // unknown flag
  ExpectInvalid(Seal(b.substr(0, b.size() - kHashSectionSize)), "flag");
  b = bytes;
  b[6] ^= 1;  // says quantized, carries POSL
  ExpectInvalid(Seal(b.substr(0, b.size() - kHashSectionSize)), "quantized flag");
  b = bytes;
  b[6] ^= 2;  // region column presence flipped: column count mismatch
  ExpectInvalid(Seal(b.substr(0, b.size() - kHashSectionSize)), "region flag");
}

TEST(MalformedTest, SectionStructure) {
  const mesh::TetMesh m = SmallMesh();
  const Parts good = Split(Encode(m));

  Parts p = good;
  p.sections.push_back(p.sections[0]);
  ExpectInvalid(Join(p), "duplicate section");

  p = good;
  p.sections.erase(p.sections.begin() + 3);
  ExpectInvalid(Join(p), "missing section");

  p = good;
  p.sections.insert(p.sections.begin() + 2, {"XTRA", "abc"});
  ExpectInvalid(Join(p), "unknown required section");

  // An unknown ancillary section is skipped, and sections may come in any order.
  p = good;
  p.sections.insert(p.sections.begin() + 2, {"xtra", "abc"});
  std::swap(p.sections[0], p.sections[4]);
  absl::StatusOr<mesh::TetMesh> back = DecodeTetMesh(Join(p));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->tets, m.tets);

  // A section length pointing past the end.
  std::string body = Encode(m);
  body.resize(body.size() - kHashSectionSize);
  ByteWriter w;
  w.Bytes(body.substr(0, 8));
  w.Bytes("PROV");
  w.U64(~uint64_t{0});
  w.Bytes(body.substr(8 + 12));
  ExpectInvalid(Seal(w.str()), "huge section length");

  // Trailing bytes inside PROV and CNTS.
  p = good;
  SectionPayload(p, "PROV") += "x";
  ExpectInvalid(Join(p), "PROV trailing");
  p = good;
  SectionPayload(p, "CNTS") += "x";
  ExpectInvalid(Join(p), "CNTS trailing");
  // A string length past its section.
  p = good;
  SectionPayload(p, "PROV")[3] = 0x7F;
  ExpectInvalid(Join(p), "PROV string length");
}

std::string Counts(uint32_t nv, uint32_t ni, uint32_t nt, uint32_t ntri, uint32_t nreg) {
  ByteWriter c;
  c.U32(nv);
  c.U32(ni);
  c.U32(nt);
  c.U32(ntri);
  c.U32(nreg);
  for (uint32_t i = 0; i < nreg && i < 2; ++i) {  // never more than 2 entries
    c.F64(0);
    c.F64(0);
  }
  return std::move(c.str());
}

TEST(MalformedTest, CountsAreBoundedBeforeAllocation) {
  const mesh::TetMesh m = SmallMesh();
  const Parts good = Split(Encode(m));
  const uint32_t nv = static_cast<uint32_t>(m.positions.size());
  const uint32_t nt = static_cast<uint32_t>(m.tets.size());
  const uint32_t ntri = static_cast<uint32_t>(m.triangles.size());

  Parts p = good;
  // Two billion tets claimed by a container of a few hundred bytes: refused
  // on the counts alone (ASan would report an allocation of ~40 GB otherwise).
  SectionPayload(p, "CNTS") = Counts(nv, 8, 0x7FFFFFFF, ntri, 2);
  ExpectInvalid(Join(p), "huge tet count");
  SectionPayload(p, "CNTS") = Counts(0x7FFFFFFF, 8, nt, ntri, 2);
  ExpectInvalid(Join(p), "huge vertex count");
  SectionPayload(p, "CNTS") = Counts(0x80000000u, 8, nt, ntri, 2);
  ExpectInvalid(Join(p), "vertex count over the format limit");
  // Regions: the table must match the length (no allocation by the count).
  SectionPayload(p, "CNTS") = Counts(nv, 8, nt, ntri, 0xFFFFFFFF);
  ExpectInvalid(Join(p), "huge region count");
  SectionPayload(p, "CNTS") = Counts(nv, 8, nt, ntri, 3);
  ExpectInvalid(Join(p), "region table shorter than its count");
  SectionPayload(p, "CNTS") = Counts(nv, nv + 1, nt, ntri, 2);
  ExpectInvalid(Join(p), "more input vertices than vertices");
  // Counts that disagree with the Draco parts.
  SectionPayload(p, "CNTS") = Counts(nv - 1, 8, nt, ntri, 2);
  ExpectInvalid(Join(p), "vertex count off by one");
  SectionPayload(p, "CNTS") = Counts(nv, 8, nt + 1, ntri, 2);
  ExpectInvalid(Join(p), "tet count off by one");
  SectionPayload(p, "CNTS") = Counts(nv, 8, nt, 0, 2);
  ExpectInvalid(Join(p), "no triangles but bytes");

  // 100M tets behind a Draco header patched to agree: only the memory limit
  // stands between this and Draco sizing its buffers by the count.
  p = good;
  SectionPayload(p, "CNTS") = Counts(nv, 8, 100000000, ntri, 2);
  std::string& tets = SectionPayload(p, "TETS");
  const uint32_t big = 100000000;
  for (int i = 0; i < 4; ++i) tets[11 + i] = static_cast<char>((big >> (8 * i)) & 0xFF);
  const absl::StatusOr<mesh::TetMesh> refused = DecodeTetMesh(Join(p));
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(refused.status().message().find("over the decoder's limit"), std::string::npos)
      << refused.status();

  // The caller's own limit.
  DecodeOptions tight;
  tight.max_mesh_bytes = 100;
  EXPECT_EQ(DecodeTetMesh(Join(good), tight).status().code(), absl::StatusCode::kInvalidArgument);
  DecodeOptions enough;
  enough.max_mesh_bytes = nv * 24 + nt * 20 + ntri * 16;
  EXPECT_TRUE(DecodeTetMesh(Join(good), enough).ok());
}

TEST(MalformedTest, IdsOutOfRange) {
  // Validly coded tets whose ids run past the vertex count.
  mesh::TetMesh m = SmallMesh();
  Parts p = Split(Encode(m));
  const uint32_t nv = static_cast<uint32_t>(m.positions.size());
  const uint32_t nt = static_cast<uint32_t>(m.tets.size());
  // Columns: first-id delta (hi, lo), three offsets (hi, lo), region (hi, lo).
  std::vector<Column> cols(10, Column(nt, 0));
  cols[1][nt - 1] = static_cast<uint16_t>(nv);  // last tet's first id jumps to nv
  absl::StatusOr<std::string> blob = EncodeColumns(cols, nt);
  ASSERT_TRUE(blob.ok());
  SectionPayload(p, "TETS") = *blob;
  ExpectInvalid(Join(p), "tet id == num_vertices");
  // A negative offset wrapping to a huge id.
  cols.assign(10, Column(nt, 0));
  cols[2][0] = 0xFFFF;
  cols[3][0] = 0xFFFF;
  blob = EncodeColumns(cols, nt);
  ASSERT_TRUE(blob.ok());
  SectionPayload(p, "TETS") = *blob;
  ExpectInvalid(Join(p), "tet id wraps to 2^32 - 1");
  // Too few columns for the flags.
  cols.assign(8, Column(nt, 0));
  blob = EncodeColumns(cols, nt);
  ASSERT_TRUE(blob.ok());
  SectionPayload(p, "TETS") = *blob;
  ExpectInvalid(Join(p), "tet columns without the region column");
  // A Draco blob that claims another point count.
  p = Split(Encode(m));
  std::string& tris = SectionPayload(p, "TRIS");
  tris[11] ^= 1;
  ExpectInvalid(Join(p), "Draco point count");
  p = Split(Encode(m));
  SectionPayload(p, "TRIS")[5] = 1;  // Draco bitstream version 1.x
  ExpectInvalid(Join(p), "Draco version");
}

TEST(MalformedTest, BadLattices) {
  const mesh::TetMesh m = SmallMesh();
  const Parts good = Split(Encode(m, 8));
  // POSQ: u8 bits, u32 exponent, 3 x i64 origin, Draco blob.
  auto with = [&](auto edit) {
    Parts p = good;
    std::string& posq = SectionPayload(p, "POSQ");
    edit(posq);
    return Join(p);
  };
  ExpectInvalid(with([](std::string& s) { s[0] = 0; }), "0 bits");
  ExpectInvalid(with([](std::string& s) { s[0] = 25; }), "25 bits");
  ExpectInvalid(with([](std::string& s) { s[0] = 20; }), "bits disagree with the columns");
  ExpectInvalid(with([](std::string& s) { s[0] = 7; }), "indices over 2^bits");
  ExpectInvalid(with([](std::string& s) { s[1] = 0; s[2] = 0x10; }), "exponent 4096");
  ExpectInvalid(with([](std::string& s) { s[1] = 0; s[2] = 0x04; s[3] = 0; s[4] = 0; }),
                "exponent 1024");
  ExpectInvalid(with([](std::string& s) { s[12] = 0x7F; }), "origin >= 2^53");
  ExpectInvalid(with([](std::string& s) { s.resize(8); }), "short POSQ");
}

}  // namespace
}  // namespace svrc::codec
