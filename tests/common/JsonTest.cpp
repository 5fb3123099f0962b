#include <gtest/gtest.h>

#include <cmath>

#include "urbanslam/common/Json.h"

using urbanslam::common::Json;

TEST(Json, KeepsKeyOrderAndEscapes) {
  Json j = Json::object();
  j["b"] = 1;
  j["a"] = "x\"y\n";
  j["c"]["nested"] = true;
  j["d"] = Json::arrayOf(std::vector<double>{0.5, 2});
  j["e"] = std::nan("");
  EXPECT_EQ(j.dump(), R"({"b":1,"a":"x\"y\n","c":{"nested":true},"d":[0.5,2],"e":null})");
  EXPECT_EQ(j.at("b").asNumber(), 1.0);
  EXPECT_TRUE(j.contains("c"));
  EXPECT_FALSE(j.contains("z"));
}
