#pragma once
// The vocabulary file: compact binary, little-endian, loaded with a handful of bulk reads so a
// 10^6-word tree loads in a fraction of a second (text vocabularies take minutes in DBoW2).
//
//   offset  size  field
//   0       8     magic "USVOCAB\0"
//   8       4     format version (kVocabularyFormatVersion)
//   12      4     descriptor type (1 SIFT, 2 ORB)
//   16      4     branching k        20  4  depth L
//   24      8     node count         32  8  word count
//   40      8     training images    48  8  training descriptors
//   56      ...   first_child u32[nodes], child_count u32[nodes], word_of_node u32[nodes],
//                 centres u8[nodes × bytes], inverse_norms f32[nodes] (SIFT only),
//                 node_of_word u32[words], idf f32[words]
//   end−8   8     checksum: 64-bit FNV-1a over 8-byte little-endian words of everything before
//                 it (the tail zero-padded), so truncation and bit flips are caught.
//
// Files are written atomically (a temporary beside the target, renamed when complete).
#include <cstdint>
#include <string>

#include "urbanslam/vision_loop/Vocabulary.h"

namespace urbanslam::vision_loop {

constexpr uint32_t kVocabularyFormatVersion = 1;

// Throws common::InputError when the file cannot be written.
void saveVocabulary(const Vocabulary& vocabulary, const std::string& path);

// Throws common::InputError naming the file for: missing file, wrong magic (not a vocabulary),
// another format version, truncation, checksum mismatch (corruption), inconsistent tree.
Vocabulary loadVocabulary(const std::string& path);

}  // namespace urbanslam::vision_loop
