#pragma once
// Descriptor kinds and the two similarity measures of the vocabulary tree. Every descriptor is
// held as bytes: OpenCV computes SIFT's 128 components as saturated 8-bit values anyway
// (the descriptor is scaled to norm 512 and clamped at 255), so uint8 loses nothing and makes a
// 10^6-word SIFT vocabulary 4x smaller than float; ORB is 256 bits = 32 bytes.
#include <cstdint>
#include <string>

namespace urbanslam::vision_loop {

enum class DescriptorType : uint32_t { Sift = 1, Orb = 2 };

// Bytes per descriptor: 128 (SIFT), 32 (ORB).
int descriptorBytes(DescriptorType type);
// "sift" / "orb".
std::string descriptorName(DescriptorType type);
// Parses "sift" / "orb" (case-insensitive); throws common::InputError otherwise.
DescriptorType parseDescriptorType(const std::string& name);

// SIFT words are compared by angle (§4.2.3: the child with the smallest angle to the
// descriptor wins): the largest dot(d, c) / |c| (|d| is common to all children).
int32_t dotProduct(const uint8_t* a, const uint8_t* b, int bytes);
// ORB words are compared by Hamming distance; `bytes` is a multiple of 8.
int hammingDistance(const uint8_t* a, const uint8_t* b, int bytes);

}  // namespace urbanslam::vision_loop
