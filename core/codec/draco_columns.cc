#include "core/codec/draco_columns.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <memory>

#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "draco/attributes/geometry_attribute.h"
#include "draco/attributes/point_attribute.h"
#include "draco/compression/config/compression_shared.h"
#include "draco/compression/decode.h"
#include "draco/compression/expert_encode.h"
#include "draco/core/decoder_buffer.h"
#include "draco/core/encoder_buffer.h"
#include "draco/point_cloud/point_cloud.h"

namespace svrc::codec {
namespace {

// Draco speed 0 = symbol-coding compression level 10 (finest rANS precision);
// decoding is as fast as at other levels. Part of the byte format in effect:
// changing it changes the reference container (tests/codec/data).
constexpr int kDracoSpeed = 0;

// The fixed start of every blob EncodeColumns writes: "DRACO", bitstream 2.3,
// point cloud (0), sequential method (0), flags 0 (no metadata); then the
// int32 point count (PointCloudSequentialEncoder::EncodeGeometryData).
constexpr char kDracoHeader[] = {'D', 'R', 'A', 'C', 'O', 2, 3, 0, 0, 0, 0};
constexpr size_t kDracoHeaderSize = sizeof(kDracoHeader);

// Order-0 entropy in bits of `values` (16-bit alphabet).
double Entropy(const std::vector<uint32_t>& histogram, size_t n) {
  double bits = 0;
  for (uint32_t c : histogram) {
    if (c != 0) bits += c * std::log2(static_cast<double>(n) / c);
  }
  return bits;
}

// Draco's DIFFERENCE prediction on a sequential integer attribute codes
// v[i] - v[i-1] wrapped into the value range; with 16-bit columns that is the
// difference mod 2^16, which is what this estimates.
bool PreferDifference(const Column& col) {
  if (col.size() < 2) return false;
  std::vector<uint32_t> raw(1 << 16, 0), diff(1 << 16, 0);
  uint16_t prev = 0;
  for (uint16_t v : col) {
    ++raw[v];
    ++diff[static_cast<uint16_t>(v - prev)];
    prev = v;
  }
  // A margin so that near-ties (where log2 rounding could differ between
  // libms) keep the simpler scheme.
  return Entropy(diff, col.size()) < 0.98 * Entropy(raw, col.size());
}

absl::Status Invalid(std::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("container: Draco part: ", std::string(what)));
}

}  // namespace

absl::StatusOr<std::string> EncodeColumns(const std::vector<Column>& columns, uint32_t n) {
  if (n > kMaxElements) {
    return absl::ResourceExhaustedError(absl::StrCat("container: ", n, " elements exceed ", kMaxElements));
  }
  for (const Column& c : columns) {
    if (c.size() != n) return absl::InternalError("container: column size mismatch");
  }
  if (n == 0 || columns.empty()) return std::string();
  try {
    draco::PointCloud pc;
    pc.set_num_points(n);
    std::vector<int> ids;
    for (const Column& c : columns) {
      draco::GeometryAttribute ga;
      ga.Init(draco::GeometryAttribute::GENERIC, nullptr, 1, draco::DT_UINT16, false,
              sizeof(uint16_t), 0);
      const int id = pc.AddAttribute(ga, /*identity_mapping=*/true, n);
      if (id < 0) return absl::InternalError("container: Draco AddAttribute failed");
      pc.attribute(id)->buffer()->Write(0, c.data(), c.size() * sizeof(uint16_t));
      ids.push_back(id);
    }
    draco::ExpertEncoder encoder(pc);
    encoder.SetEncodingMethod(draco::POINT_CLOUD_SEQUENTIAL_ENCODING);
    encoder.SetSpeedOptions(kDracoSpeed, kDracoSpeed);
    for (size_t i = 0; i < columns.size(); ++i) {
      const int method = PreferDifference(columns[i]) ? draco::PREDICTION_DIFFERENCE
                                                      : draco::PREDICTION_NONE;
      const draco::Status s = encoder.SetAttributePredictionScheme(ids[i], method);
      if (!s.ok()) return absl::InternalError(absl::StrCat("container: Draco: ", s.error_msg()));
    }
    draco::EncoderBuffer buffer;
    const draco::Status s = encoder.EncodeToBuffer(&buffer);
    if (!s.ok()) return absl::InternalError(absl::StrCat("container: Draco encode: ", s.error_msg()));
    std::string out(buffer.data(), buffer.size());
    if (out.size() < kDracoHeaderSize + 4 ||
        std::memcmp(out.data(), kDracoHeader, kDracoHeaderSize) != 0) {
      return absl::InternalError(
          absl::StrCat("container: unexpected Draco header (Draco version changed?): ",
                       absl::BytesToHexString(absl::string_view(out.data(), std::min<size_t>(out.size(), 16)))));
    }
    return out;
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("container: Draco encode threw: ", e.what()));
  }
}

absl::StatusOr<std::vector<Column>> DecodeColumns(std::string_view blob, uint32_t n,
                                                  size_t num_columns) {
  if (n == 0 || num_columns == 0) {
    if (!blob.empty()) return Invalid("bytes for an empty part");
    return std::vector<Column>(num_columns);
  }
  // Check the header and the point count before Draco sizes any buffer by it.
  if (blob.size() < kDracoHeaderSize + 4 ||
      std::memcmp(blob.data(), kDracoHeader, kDracoHeaderSize) != 0) {
    return Invalid("not a Draco 2.3 sequential point cloud without metadata");
  }
  uint32_t count = 0;
  for (int i = 0; i < 4; ++i) {
    count |= static_cast<uint32_t>(static_cast<uint8_t>(blob[kDracoHeaderSize + i])) << (8 * i);
  }
  if (count != n) return Invalid(absl::StrCat(count, " points where the counts say ", n));
  try {
    draco::DecoderBuffer buffer;
    buffer.Init(blob.data(), blob.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodePointCloudFromBuffer(&buffer);
    if (!decoded.ok()) return Invalid(decoded.status().error_msg());
    const draco::PointCloud& pc = *decoded.value();
    if (pc.num_points() != n) return Invalid("point count mismatch");
    if (pc.num_attributes() != static_cast<int32_t>(num_columns)) {
      return Invalid(absl::StrCat(pc.num_attributes(), " attributes, expected ", num_columns));
    }
    std::vector<Column> columns(num_columns);
    for (size_t i = 0; i < num_columns; ++i) {
      const draco::PointAttribute* att = pc.attribute(static_cast<int32_t>(i));
      if (att == nullptr || att->data_type() != draco::DT_UINT16 || att->num_components() != 1 ||
          att->byte_stride() != sizeof(uint16_t) || att->buffer() == nullptr) {
        return Invalid("attribute of the wrong type");
      }
      const size_t values = att->size();
      const size_t data_size = att->buffer()->data_size();
      const int64_t offset = att->byte_offset();
      if (offset < 0 || static_cast<uint64_t>(offset) > data_size ||
          (data_size - offset) / sizeof(uint16_t) < values) {
        return Invalid("attribute buffer too small");
      }
      const uint8_t* base = att->buffer()->data() + offset;
      Column& col = columns[i];
      col.resize(n);
      if (att->is_mapping_identity()) {
        if (values < n) return Invalid("attribute has fewer values than points");
        std::memcpy(col.data(), base, n * sizeof(uint16_t));
      } else {
        for (uint32_t p = 0; p < n; ++p) {
          if (att->indices_map_size() <= p) return Invalid("short point map");
          const uint32_t v = att->mapped_index(draco::PointIndex(p)).value();
          if (v >= values) return Invalid("point maps outside the values");
          std::memcpy(&col[p], base + v * sizeof(uint16_t), sizeof(uint16_t));
        }
      }
    }
    return columns;
  } catch (const std::exception& e) {
    return Invalid(absl::StrCat("Draco decode threw: ", e.what()));
  }
}

}  // namespace svrc::codec
