// Columns of 16-bit integers coded as one Draco point cloud (sequential
// encoding, one 1-component DT_UINT16 attribute per column): the building
// block of every coded section of the result container (docs/container.md).
// 16-bit columns keep every Draco entropy-coder symbol below 2^18, away from
// the memory hazard of large symbols (notes/dependencies.md, upstream #451).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace svrc::codec {

using Column = std::vector<uint16_t>;

// Draco's point count is an int32: every coded section holds fewer elements.
inline constexpr uint32_t kMaxElements = 0x7FFFFFFFu;

// Encodes `columns` (each of `n` values; n <= kMaxElements) as a Draco point
// cloud with n points. Per column, Draco's prediction is DIFFERENCE or NONE,
// whichever an order-0 entropy estimate prefers. Point order is kept (forced
// sequential encoding). n == 0 gives an empty string. Deterministic.
absl::StatusOr<std::string> EncodeColumns(const std::vector<Column>& columns, uint32_t n);

// Decodes a blob written by EncodeColumns, which must hold exactly `n` points
// and `num_columns` attributes of the expected type; anything else is
// INVALID_ARGUMENT. The Draco header (version, point count) is checked before
// Draco allocates anything.
absl::StatusOr<std::vector<Column>> DecodeColumns(std::string_view blob, uint32_t n,
                                                  size_t num_columns);

}  // namespace svrc::codec
