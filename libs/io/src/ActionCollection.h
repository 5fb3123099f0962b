#pragma once
// A rawlog's CActionCollection read element by element (internal to libs/io). MRPT's own reader
// takes whatever object comes next as an action and dereferences it: an observation where an
// action should be (a corrupt or hand-made file) crashes it. Here each element's class is looked
// at before it is read, and only MRPT's actions are read.
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/serialization/CArchive.h>

#include <cctype>
#include <string>

#include "urbanslam/common/Error.h"

namespace urbanslam::io::detail {

// The byte MRPT writes after every serialised object.
constexpr uint8_t kEndOfObject = 0x88;

// Reads a CActionCollection whose header comes next in `arch` (whose stream supports
// peekClassName()). Throws common::InputError naming `where` for anything but actions.
template <typename PeekingStream>
mrpt::obs::CActionCollection::Ptr readActionCollection(mrpt::serialization::CArchive& arch, PeekingStream& stream, const std::string& where) {
  const auto bad = [&](const std::string& why) { return common::InputError(where + ": corrupt rawlog: mrpt::obs::CActionCollection " + why); };
  const std::string name = stream.peekClassName();
  std::string header(1 + name.size(), '\0');
  arch.ReadBuffer(header.data(), header.size());
  uint8_t version = 0;
  arch >> version;
  if (version != 0) throw bad("of unknown version " + std::to_string(version));
  uint32_t count = 0;
  arch >> count;
  auto acts = mrpt::obs::CActionCollection::Create();
  for (uint32_t i = 0; i < count; ++i) {
    std::string cls = stream.peekClassName();
    if (cls.rfind("mrpt::obs::", 0) == 0) cls.erase(0, 11);
    if (cls != "CActionRobotMovement2D" && cls != "CActionRobotMovement3D") {
      for (char& c : cls)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != ':') c = '?';
      throw bad("holds " + (cls.empty() ? std::string("something") : "a " + cls.substr(0, 40)) + " where an action should be");
    }
    auto action = std::dynamic_pointer_cast<mrpt::obs::CAction>(arch.ReadObject());
    if (!action) throw bad("holds a null action");
    acts->insert(*action);
  }
  // MRPT ends every object with a marker byte.
  uint8_t end = 0;
  arch >> end;
  if (end != kEndOfObject) throw bad("does not end where its actions do");
  return acts;
}

}  // namespace urbanslam::io::detail
