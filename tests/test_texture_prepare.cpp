// Large textures' mip chains made on the CPU (common/images/texture_prepare.h): the box
// filter in linear light for sRGB colour and as stored for linear data, checked at
// known texels against the same means computed in double with the sRGB formulas
// themselves; odd sides, chain sizes and the S3TC block layout.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "images/texture_prepare.h"

namespace {

// The sRGB encoding (IEC 61966-2-1), the inverse of kit::srgb_to_linear, in double.
double linear_to_srgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

// The 8-bit code a mean lands on: sRGB codes through linear light, or data as stored.
unsigned char expected_mean(const std::vector<unsigned char>& codes, const std::vector<double>& weights, bool srgb) {
  double sum = 0.0, total = 0.0;
  for (size_t i = 0; i < codes.size(); ++i) {
    sum += weights[i] * (srgb ? kit::srgb_to_linear(codes[i] / 255.0) : static_cast<double>(codes[i]));
    total += weights[i];
  }
  const double mean = sum / total;
  return static_cast<unsigned char>(std::lround(srgb ? 255.0 * linear_to_srgb(mean) : mean));
}

// A width x height image whose texel (x, y) channel c is `value(x, y, c)`.
template <typename F>
kit::ImageRgba8 image_of(int width, int height, F value) {
  kit::ImageRgba8 image;
  image.width = width;
  image.height = height;
  image.pixels.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 4; ++c)
        image.pixels[(static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 4 + static_cast<size_t>(c)] =
            value(x, y, c);
  return image;
}

unsigned char texel(const kit::ImageRgba8& image, int x, int y, int c) {
  return image.pixels[(static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x)) * 4 + static_cast<size_t>(c)];
}

// Texels with detail everywhere: every 2x2 footprint holds four different codes.
unsigned char detailed(int x, int y, int c) { return static_cast<unsigned char>((x * 67 + y * 151 + c * 89 + x * y * 13) % 256); }

}  // namespace

TEST(TexturePrepare, SrgbColourIsAveragedInLinearLightAlphaAsStored) {
  const kit::ImageRgba8 level = image_of(8, 6, detailed);
  const kit::ImageRgba8 next = kit::next_mip_level(level, true);
  ASSERT_EQ(next.width, 4);
  ASSERT_EQ(next.height, 3);
  size_t differs_from_code_mean = 0;
  for (int y = 0; y < next.height; ++y)
    for (int x = 0; x < next.width; ++x)
      for (int c = 0; c < 4; ++c) {
        const std::vector<unsigned char> codes = {texel(level, 2 * x, 2 * y, c), texel(level, 2 * x + 1, 2 * y, c),
                                                  texel(level, 2 * x, 2 * y + 1, c), texel(level, 2 * x + 1, 2 * y + 1, c)};
        const std::vector<double> equal(4, 1.0);
        const bool colour = c < 3;
        EXPECT_EQ(texel(next, x, y, c), expected_mean(codes, equal, colour)) << "texel (" << x << ", " << y << ") channel " << c;
        // Witness: the mean of the codes themselves is another value for most colour texels.
        if (colour && expected_mean(codes, equal, false) != texel(next, x, y, c)) ++differs_from_code_mean;
      }
  EXPECT_GT(differs_from_code_mean, 24u) << "of 36 colour values, too few tell linear light from stored codes";
}

TEST(TexturePrepare, BlackAndWhiteMeetAtLinearMiddleGrey) {
  // The classic case: half black, half white is 50 % of the light, sRGB code 188, not 128.
  const kit::ImageRgba8 level = image_of(2, 2, [](int x, int, int) { return static_cast<unsigned char>(x == 0 ? 0 : 255); });
  EXPECT_EQ(texel(kit::next_mip_level(level, true), 0, 0, 0), 188);
  EXPECT_EQ(texel(kit::next_mip_level(level, false), 0, 0, 0), 128);  // linear data: 127.5, rounded half up
  EXPECT_EQ(texel(kit::next_mip_level(level, true), 0, 0, 3), 128);   // alpha is data in either
}

TEST(TexturePrepare, LinearDataIsAveragedAsStored) {
  const kit::ImageRgba8 level = image_of(6, 4, detailed);
  const kit::ImageRgba8 next = kit::next_mip_level(level, false);
  for (int y = 0; y < next.height; ++y)
    for (int x = 0; x < next.width; ++x)
      for (int c = 0; c < 4; ++c) {
        const std::vector<unsigned char> codes = {texel(level, 2 * x, 2 * y, c), texel(level, 2 * x + 1, 2 * y, c),
                                                  texel(level, 2 * x, 2 * y + 1, c), texel(level, 2 * x + 1, 2 * y + 1, c)};
        EXPECT_EQ(texel(next, x, y, c), expected_mean(codes, std::vector<double>(4, 1.0), false))
            << "texel (" << x << ", " << y << ") channel " << c;
      }
}

TEST(TexturePrepare, AnOddSideIsBoxFilteredByTheCoveredParts) {
  // 5 texels to 2: each covers 2.5 source texels, the middle one half each.
  const kit::ImageRgba8 level = image_of(5, 1, detailed);
  const kit::ImageRgba8 next = kit::next_mip_level(level, true);
  ASSERT_EQ(next.width, 2);
  ASSERT_EQ(next.height, 1);
  for (int c = 0; c < 4; ++c) {
    const bool colour = c < 3;
    EXPECT_EQ(texel(next, 0, 0, c), expected_mean({texel(level, 0, 0, c), texel(level, 1, 0, c), texel(level, 2, 0, c)},
                                                  {1.0, 1.0, 0.5}, colour)) << "channel " << c;
    EXPECT_EQ(texel(next, 1, 0, c), expected_mean({texel(level, 2, 0, c), texel(level, 3, 0, c), texel(level, 4, 0, c)},
                                                  {0.5, 1.0, 1.0}, colour)) << "channel " << c;
  }
  // 3 texels to 1 weighs them alike.
  const kit::ImageRgba8 three = kit::next_mip_level(image_of(3, 3, detailed), false);
  std::vector<unsigned char> codes;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) codes.push_back(detailed(x, y, 1));
  EXPECT_EQ(texel(three, 0, 0, 1), expected_mean(codes, std::vector<double>(9, 1.0), false));
}

// The float chain (environment maps): the same box filter, values as stored, HDR
// values above 1 kept; an even side averages 2 x 2, an odd one by the covered parts.
TEST(TexturePrepare, FloatLevelsAreBoxFilteredAsStored) {
  kit::Image level(5, 2, 3);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 5; ++x)
      for (int c = 0; c < 3; ++c) level.at(x, y, c) = static_cast<float>(0.37 * x * x + 11.0 * y + 2.5 * c);  // up to 22
  const kit::Image next = kit::next_mip_level(level);
  ASSERT_EQ(next.width, 2);
  ASSERT_EQ(next.height, 1);
  ASSERT_EQ(next.channels, 3);
  for (int c = 0; c < 3; ++c) {
    auto column_mean = [&](int x) { return (double{level.at(x, 0, c)} + double{level.at(x, 1, c)}) / 2.0; };
    const double left = (column_mean(0) + column_mean(1) + 0.5 * column_mean(2)) / 2.5;
    const double right = (0.5 * column_mean(2) + column_mean(3) + column_mean(4)) / 2.5;
    EXPECT_NEAR(next.at(0, 0, c), left, 1e-5 * left) << "channel " << c;
    EXPECT_NEAR(next.at(1, 0, c), right, 1e-5 * right) << "channel " << c;
  }
  const kit::Image one = kit::next_mip_level(kit::next_mip_level(next));
  EXPECT_EQ(one.width, 1);
  EXPECT_EQ(one.height, 1);
}

TEST(TexturePrepare, ChainGoesDownToOneTexelAndCompressesToBlocks) {
  const kit::ImageRgba8 opaque = image_of(10, 3, [](int x, int y, int c) { return c == 3 ? 255 : detailed(x, y, c); });
  const kit::PreparedTexture plain = kit::prepare_texture(opaque, true, false);
  EXPECT_EQ(plain.encoding, kit::TexelEncoding::Rgba8);
  const std::vector<std::pair<int, int>> sizes = {{10, 3}, {5, 1}, {2, 1}, {1, 1}};
  ASSERT_EQ(plain.levels.size(), sizes.size());
  for (size_t l = 0; l < sizes.size(); ++l) {
    EXPECT_EQ(plain.levels[l].width, sizes[l].first) << "level " << l;
    EXPECT_EQ(plain.levels[l].height, sizes[l].second) << "level " << l;
    EXPECT_EQ(plain.levels[l].bytes.size(), static_cast<size_t>(sizes[l].first * sizes[l].second * 4)) << "level " << l;
  }
  EXPECT_EQ(plain.levels[0].bytes, opaque.pixels);
  EXPECT_EQ(plain.levels[1].bytes, kit::next_mip_level(opaque, true).pixels);

  // Compressed: BC1 when opaque (8 bytes a 4x4 block, sides padded to whole blocks), BC3 (16) with alpha.
  const kit::PreparedTexture bc1 = kit::prepare_texture(opaque, true, true);
  EXPECT_EQ(bc1.encoding, kit::TexelEncoding::Bc1);
  const std::vector<size_t> bc1_bytes = {3 * 1 * 8, 2 * 1 * 8, 8, 8};
  ASSERT_EQ(bc1.levels.size(), bc1_bytes.size());
  for (size_t l = 0; l < bc1_bytes.size(); ++l) EXPECT_EQ(bc1.levels[l].bytes.size(), bc1_bytes[l]) << "level " << l;
  kit::ImageRgba8 translucent = opaque;
  translucent.pixels[3] = 254;
  EXPECT_FALSE(kit::is_opaque(translucent));
  const kit::PreparedTexture bc3 = kit::prepare_texture(translucent, true, true);
  EXPECT_EQ(bc3.encoding, kit::TexelEncoding::Bc3);
  EXPECT_EQ(bc3.levels[0].bytes.size(), 3u * 1u * 16u);
}

TEST(TexturePrepare, OnlyLargeTexturesAreLarge) {
  EXPECT_TRUE(kit::is_large_texture(1024, 1024));
  EXPECT_TRUE(kit::is_large_texture(4096, 256));
  EXPECT_FALSE(kit::is_large_texture(1024, 1023));
  EXPECT_FALSE(kit::is_large_texture(256, 256));  // the kit scenes' textures
}

// Whether a scene's large textures are compressed (texture_compression.h): by the
// budget on a CPU rasteriser, always on a GPU, and as --compress-textures on|off says.
TEST(TextureCompression, AutoCompressesOverTheBudgetOrOnAGpu) {
  const std::string llvmpipe = "llvmpipe (LLVM 15.0.6, 256 bits)", gpu = "NVIDIA H100 80GB HBM3/PCIe/SSE2";
  // The heavy scene (kit-scenes --heavy): 16 base colours of 2048x2048, 341 MiB with mips.
  const size_t heavy = 16 * kit::rgba8_chain_bytes(2048, 2048);
  EXPECT_EQ(heavy >> 20, 341u);
  // LearnOpenGL's nanosuit: five 1024x1024 diffuse maps and one of 128x128, 27 MiB.
  const size_t nanosuit = 5 * kit::rgba8_chain_bytes(1024, 1024) + kit::rgba8_chain_bytes(128, 128);
  ASSERT_LT(nanosuit, kit::kTextureMemoryBudgetBytes);
  ASSERT_GT(heavy, kit::kTextureMemoryBudgetBytes);
  auto decide = [](kit::TextureCompression mode, size_t bytes, bool any_large, const std::string& renderer,
                   const std::string& s3tc_unavailable = "") {
    return kit::decide_texture_compression(mode, bytes, any_large, renderer, s3tc_unavailable);
  };
  using kit::TextureCompression;
  const kit::TextureCompressionDecision over = decide(TextureCompression::Auto, heavy, true, llvmpipe);
  EXPECT_TRUE(over.compress);
  EXPECT_EQ(over.reason, "textures: 341 MiB uncompressed, over the 256 MiB budget: large ones compressed to S3TC");
  const kit::TextureCompressionDecision fits = decide(TextureCompression::Auto, nanosuit, true, llvmpipe);
  EXPECT_FALSE(fits.compress);
  EXPECT_EQ(fits.reason,
            "textures: 27 MiB uncompressed, budget 256 MiB: not compressed (llvmpipe decodes S3TC in software, "
            "slower to sample)");
  EXPECT_FALSE(decide(TextureCompression::Auto, nanosuit, true, "softpipe").compress);
  EXPECT_TRUE(decide(TextureCompression::Auto, nanosuit, true, gpu).compress);
  EXPECT_FALSE(decide(TextureCompression::Auto, heavy, false, gpu).compress) << "nothing large: nothing to compress";
  // The overrides, both ways.
  EXPECT_TRUE(decide(TextureCompression::On, nanosuit, true, llvmpipe).compress);
  const kit::TextureCompressionDecision off = decide(TextureCompression::Off, heavy, true, llvmpipe);
  EXPECT_FALSE(off.compress);
  EXPECT_NE(off.reason.find("(--compress-textures off)"), std::string::npos) << off.reason;
  EXPECT_FALSE(decide(TextureCompression::Off, nanosuit, true, gpu).compress);
  // A context without the S3TC formats uploads RGBA8 whatever was asked, and says why.
  const kit::TextureCompressionDecision missing =
      decide(TextureCompression::On, heavy, true, llvmpipe, "the GL context lacks GL_EXT_texture_compression_s3tc");
  EXPECT_FALSE(missing.compress);
  EXPECT_TRUE(missing.wanted);
  EXPECT_NE(missing.reason.find("lacks GL_EXT_texture_compression_s3tc"), std::string::npos) << missing.reason;
}

TEST(TextureCompression, CpuRasterisersAreToldFromGpusByName) {
  EXPECT_TRUE(kit::renders_on_cpu("llvmpipe (LLVM 15.0.6, 256 bits)"));
  EXPECT_TRUE(kit::renders_on_cpu("softpipe"));
  EXPECT_TRUE(kit::renders_on_cpu("Mesa X11 Software Rasterizer"));
  EXPECT_TRUE(kit::renders_on_cpu("Google SwiftShader"));
  EXPECT_FALSE(kit::renders_on_cpu("NVIDIA H100 80GB HBM3/PCIe/SSE2"));
  EXPECT_FALSE(kit::renders_on_cpu("AMD Radeon RX 6800 (radeonsi, navi21, LLVM 15.0.6, DRM 3.49)"));
  EXPECT_FALSE(kit::renders_on_cpu("Mesa Intel(R) UHD Graphics 620 (KBL GT2)"));
}
