#pragma once
namespace spherekit {
/// Library version string, recorded in every output's provenance.
inline constexpr const char* kVersion = "0.1.0";
/// Version of the sphere-map/collection exchange formats written by this library.
inline constexpr int kFormatVersion = 1;
}  // namespace spherekit
