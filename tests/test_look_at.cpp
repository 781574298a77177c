// --look-at (common/scene/look_at.h, a shared flag of cli.h): parsing, refusals, and
// the view matrix against glm::lookAt evaluated in double.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <string>

#include "base/error.h"
#include "scene/look_at.h"
#include "scene/scene.h"

namespace {

constexpr double kMatrixTolerance = 1e-6;  // a double matrix rounded to float

std::string parse_error(const std::string& text) {
  try {
    kit::parse_look_at(text);
  } catch (const kit::Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "'" << text << "' parsed, but a kit::Error was expected";
  return "";
}

kit::Scene unit_bounds() {
  kit::Scene s;
  s.bounds_min = glm::vec3(-1.0f);
  s.bounds_max = glm::vec3(1.0f);
  return s;
}

}  // namespace

TEST(LookAt, ParsesEyeTargetAndFov) {
  const kit::LookAt a = kit::parse_look_at("1.5,2,-3,0,0.25,0");
  EXPECT_EQ(a.eye, glm::dvec3(1.5, 2.0, -3.0));
  EXPECT_EQ(a.target, glm::dvec3(0.0, 0.25, 0.0));
  EXPECT_FALSE(a.fov_degrees.has_value());
  const kit::LookAt b = kit::parse_look_at("0,0,5,0,0,0,35");
  ASSERT_TRUE(b.fov_degrees.has_value());
  EXPECT_EQ(*b.fov_degrees, 35.0);
}

TEST(LookAt, RefusesWhatIsNoCamera) {
  EXPECT_NE(parse_error("1,2,3").find("3 numbers"), std::string::npos);
  EXPECT_NE(parse_error("1,2,3,4,5,x").find("'x' is not a finite number"), std::string::npos);
  EXPECT_NE(parse_error("1,2,3,4,5,6,7,8").find("8 numbers"), std::string::npos);
  EXPECT_NE(parse_error("1,2,3,1,2,3").find("the same point"), std::string::npos);
  EXPECT_NE(parse_error("0,0,5,0,0,0,180").find("between 1 and 179"), std::string::npos);
  EXPECT_NE(parse_error("0,0,inf,0,0,0").find("not a finite number"), std::string::npos);
  EXPECT_NE(parse_error("").find("--look-at expects"), std::string::npos);
}

TEST(LookAt, ViewMatrixIsGlmLookAtInDouble) {
  const kit::Scene scene = unit_bounds();
  const kit::LookAt a = kit::parse_look_at("3,2,4,0.5,-0.25,0,40");
  const kit::Camera camera = kit::look_at_camera(a, scene);
  const glm::dmat4 expected = glm::lookAt(glm::dvec3(3, 2, 4), glm::dvec3(0.5, -0.25, 0), glm::dvec3(0, 1, 0));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(camera.view[c][r], expected[c][r], kMatrixTolerance) << c << "," << r;
  EXPECT_NEAR(camera.yfov, glm::radians(40.0), 1e-7);
  EXPECT_EQ(camera.position, glm::vec3(3, 2, 4));
  // The bounds lie between the planes: the bounding sphere (radius sqrt 3) around the origin.
  const double distance = std::sqrt(9.0 + 4.0 + 16.0), radius = std::sqrt(3.0);
  EXPECT_LT(camera.znear, distance - radius);
  EXPECT_GT(camera.zfar, distance + radius);
  EXPECT_GT(camera.znear, 0.0f);
  // Without a FOV: the framing camera's.
  EXPECT_EQ(kit::look_at_camera(kit::parse_look_at("3,2,4,0,0,0"), scene).yfov, kit::framing_camera(scene).yfov);
}

TEST(LookAt, StraightDownStillHasAnUp) {
  const kit::Camera camera = kit::look_at_camera(kit::parse_look_at("0,10,0,0,0,0"), unit_bounds());
  const glm::dmat4 expected = glm::lookAt(glm::dvec3(0, 10, 0), glm::dvec3(0), glm::dvec3(0, 0, -1));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(camera.view[c][r], expected[c][r], kMatrixTolerance);
}

TEST(LookAt, TextRoundTrips) {
  const std::string text = kit::look_at_text({1.25f, -2.0f, 3.5f}, {0.0f, 0.5f, -1.0f}, float(glm::radians(50.0)));
  EXPECT_EQ(text, "1.25,-2,3.5,0,0.5,-1,50");
  const kit::LookAt a = kit::parse_look_at(text);
  EXPECT_EQ(a.eye, glm::dvec3(1.25, -2.0, 3.5));
  EXPECT_NEAR(*a.fov_degrees, 50.0, 1e-6);
}
