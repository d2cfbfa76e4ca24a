// Size limits of a case file (docs/case-format.md, "Limits"). They keep absurd inputs
// from hanging or exhausting memory downstream; exceeding one is an InputError.
#pragma once
#include <cstddef>

namespace hm {

inline constexpr std::size_t kMaxAxisValues = 2000;         ///< per reservoir.x / y / z
inline constexpr double kMaxCells = 20e6;                   ///< reservoir + estimated well cells
inline constexpr std::size_t kMaxWells = 1000;
inline constexpr std::size_t kMaxTrajectoryPoints = 10000;  ///< over all wells together
inline constexpr std::size_t kMaxWellNameLength = 8;        ///< Eclipse well names
inline constexpr std::size_t kMaxCaseNameLength = 64;       ///< the name is used in file names
/// Largest dogleg between two survey stations: minimum curvature's arc is undefined at 180
/// degrees, and real surveys turn by a few degrees per station.
inline constexpr double kMaxSurveyDoglegDeg = 90;
inline constexpr double kDegreesToRadians = 3.14159265358979323846 / 180.0;
inline constexpr std::size_t kMaxCaseFileBytes = std::size_t(64) << 20;

}  // namespace hm
