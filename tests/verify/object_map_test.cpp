// verify/object_map.cpp: the nominal's objects (instance x geometry of each primary ray) and their image form.
#include <gtest/gtest.h>

#include "core/error.h"
#include "verify/object_map.h"

namespace refray::scenes {
namespace {

TEST(ObjectMap, RoundTripsThroughItsImage) {
    ObjectMap map;
    map.ids = {-1, objectId(0, 0), objectId(2, 3), objectId(2, 3), -1, objectId(4095, 4095)};
    map.names = {{-1, "the background"}, {objectId(0, 0), "object 'plane'"},
                 {objectId(2, 3), "object 'primitives' geometry 3"}, {objectId(4095, 4095), "object 'last'"}};
    const Image image = objectMapImage(map, 3, 2);
    EXPECT_EQ(image.at(2, 1).r, float(objectId(4095, 4095)));  // below 2^24: exact
    const ObjectMap back = objectMapOf(image);
    EXPECT_EQ(back.ids, map.ids);
    EXPECT_EQ(back.names, map.names);
}

TEST(ObjectMap, RefusesAnImageThatIsNoObjectMap) {
    Image image(2, 1, vec4(0.5f));
    image.metadata["object_names"] = "0=object 'a'";
    EXPECT_THROW(objectMapOf(image), Error);
    Image unnamed(2, 1, vec4(1.0f));
    EXPECT_THROW(objectMapOf(unnamed), Error);
}

}  // namespace
}  // namespace refray::scenes
