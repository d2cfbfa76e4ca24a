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
/// Relative slack of a perforation's md_to beyond the path's end: a trajectory's length is a
/// sum of rounded segment lengths, so an interval typed to its exact end may exceed it by ulps.
inline constexpr double kMeasuredDepthTolerance = 1e-9;
/// Largest bend between two legs of a trajectory that case validation accepts: what the bend sweep
/// of docs/robustness.md proves the transition holds (first bend-related failures measured: 75 and
/// 80 degrees on paper_single_well without optimisation, 82.5 in the bend sweep).
inline constexpr double kMaxBendDegrees = 60;
/// Largest bend a well block can be built with (the wedges' geometry; well_block.cpp).
inline constexpr double kMaxBlockBendDegrees = 120;
/// A bend counts as above the limit when it exceeds it by more than this relative amount: the
/// angle computed from typed coordinates (e.g. 30 sin 120 rounded to 6 digits) may be a hair off.
inline constexpr double kBendLimitTolerance = 1e-6;
inline constexpr double kDegreesToRadians = 3.14159265358979323846 / 180.0;
inline constexpr std::size_t kMaxCaseFileBytes = std::size_t(64) << 20;


// Physical bounds (docs/case-format.md, "Limits"): wide enough for any real model, narrow enough
// that no product the mesher, the transmissibilities or a deck form from them overflows or
// underflows (permeability 1e300 mD made inf - inf = NaN transmissibilities).
inline constexpr double kMaxAbsCoordinate = 1e8;     ///< m, any coordinate (UTM northings are < 1e7)
inline constexpr double kMinPermeability = 1e-9;     ///< mD (1 picodarcy)
inline constexpr double kMaxPermeability = 1e9;      ///< mD (1e6 darcy)
inline constexpr double kMaxPressure = 1e5;          ///< bar, initial pressure and bhp
inline constexpr double kMinWellRadius = 1e-3;       ///< m
inline constexpr double kMaxWellRadius = 10;         ///< m
inline constexpr double kMaxDrainageRadius = 1e4;    ///< m
inline constexpr double kMaxSegmentLength = 1e5;     ///< m
inline constexpr double kMinViscosity = 1e-4;        ///< cP
inline constexpr double kMaxViscosity = 1e9;         ///< cP
inline constexpr double kMinDensity = 1e-3;          ///< kg/m3
inline constexpr double kMaxDensity = 1e5;           ///< kg/m3
inline constexpr double kMaxCompressibility = 1;     ///< 1/bar

}  // namespace hm
