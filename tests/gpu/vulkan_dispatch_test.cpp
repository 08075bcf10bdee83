#include "gpu/vulkan_dispatch.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "tests/test_output.h"

namespace refray::gpu {
namespace {

namespace fs = std::filesystem;

// REFRAY_SPIRV_DIR wins; else the build tree beside the executable's folder; else the bundle's shaders/ folder.
TEST(VulkanDispatch, SpirvIsFoundByEnvironmentThenBuildTreeThenBundle) {
    const fs::path root = refray::testing::testOutputDirectory("gpu");
    fs::remove_all(root);
    fs::create_directories(root / "tools");
    fs::create_directories(root / "bundle" / "shaders");
    unsetenv("REFRAY_SPIRV_DIR");
    EXPECT_EQ(defaultSpirvDirectory(root / "bundle" / "refray"), (root / "bundle" / "shaders").lexically_normal());
    fs::create_directories(root / "gpu" / "shaders");
    EXPECT_EQ(defaultSpirvDirectory(root / "tools" / "refray"), (root / "gpu" / "shaders").lexically_normal());
    setenv("REFRAY_SPIRV_DIR", "/somewhere/else", 1);
    EXPECT_EQ(defaultSpirvDirectory(root / "tools" / "refray"), fs::path("/somewhere/else"));
    unsetenv("REFRAY_SPIRV_DIR");
}

}  // namespace
}  // namespace refray::gpu
