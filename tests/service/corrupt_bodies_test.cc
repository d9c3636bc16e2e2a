// tod_load --corrupt: every damaged body is one the server's decoder refuses as invalid (so the
// soak's "corrupt" requests really are corrupt, and each costs the server a 400, not a pipeline).
#include "client/corrupt_bodies.h"

#include <gtest/gtest.h>

#include "server/core/image_codec.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

TEST(CorruptBodiesTest, EveryBodyIsRefusedByTheDecoder) {
  const std::string frame = testing::RoadPng(320, 160);
  const std::vector<client::RequestBody> bodies = client::CorruptBodies(frame, 1);
  ASSERT_EQ(bodies.size(), 3u);
  EXPECT_EQ(bodies[0].content_type, "image/jpeg");
  EXPECT_EQ(bodies[1].content_type, "image/png");
  EXPECT_EQ(bodies[2].bytes.size(), std::max<size_t>(frame.size(), 1024));
  for (const client::RequestBody& body : bodies) {
    EXPECT_EQ(DecodeImage(body.bytes, ImageLimits{}).status().code(), StatusCode::kInvalidArgument)
        << body.name;
  }
  // Seeded: the same noise for the same seed.
  EXPECT_EQ(client::CorruptBodies(frame, 1)[2].bytes, bodies[2].bytes);
}

TEST(CorruptBodiesTest, UndecodableFrameGivesNoiseOnly) {
  const std::vector<client::RequestBody> bodies = client::CorruptBodies("not an image", 2);
  ASSERT_EQ(bodies.size(), 1u);
  EXPECT_EQ(bodies[0].name, "garbage");
}

}  // namespace
}  // namespace tod::server
