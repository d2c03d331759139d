#pragma once
/// @file
/// Angle units. Code works in radians (SI); degrees appear only at the edges (files, flags,
/// reports), in names ending in _deg, converted with these.
///
/// Threading: constants.

namespace orbed {

inline constexpr double kPi = 3.14159265358979323846;
/// Multiply degrees by this to get radians.
inline constexpr double kDegToRad = kPi / 180.0;
/// Multiply radians by this to get degrees.
inline constexpr double kRadToDeg = 180.0 / kPi;

}  // namespace orbed
