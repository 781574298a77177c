// PNG and EXR through libpng and OpenEXR (common/images/image_codecs.h), checked against
// OpenImageIO reading and writing the same files: the kit read every image through
// OpenImageIO before, and its references and scenes must read the same. JPEG and other
// formats go through OpenImageIO in a module loaded on first use (openimageio_formats.h).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "base/error.h"
#include "render/ibl.h"
#include "images/image_codecs.h"
#include "images/image_io.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "scene/scene.h"
#include "images/texture_decode.h"

namespace fs = std::filesystem;

namespace {

// Writes `values` (width x height x channels, in `type`) through OpenImageIO.
template <typename T>
void write_with_openimageio(const fs::path& path, int width, int height, int channels, OIIO::TypeDesc type,
                            const std::vector<T>& values, int x_origin = 0, int y_origin = 0) {
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(width, height, channels, type);
  spec.attribute("oiio:UnassociatedAlpha", 1);  // the values as given, not divided by alpha
  spec.x = x_origin;
  spec.y = y_origin;
  spec.full_x = x_origin;
  spec.full_y = y_origin;
  ASSERT_TRUE(out->open(path.string(), spec) && out->write_image(type, values.data()) && out->close()) << out->geterror();
}

// PNG keeps colour unassociated with alpha (as glTF and MTL mean it), and the kit reads
// it so; OpenImageIO multiplies it by alpha unless told not to.
kit::Image read_with_openimageio(const fs::path& path) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path.string(), &config);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  kit::Image image(in->spec().width, in->spec().height, in->spec().nchannels);
  EXPECT_TRUE(in->read_image(0, 0, 0, image.channels, OIIO::TypeDesc::FLOAT, image.pixels.data()));
  return image;
}

bool same_floats(const kit::Image& a, const kit::Image& b) {
  return a.width == b.width && a.height == b.height && a.channels == b.channels &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

std::vector<unsigned char> bytes_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const kit::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// 8- and 16-bit PNGs of 1 to 4 channels read as OpenImageIO reads them, bit for bit
// (8-bit v as v * (1/255): v / 255 differs in the last bit for 126 of the 256 values),
// colour unassociated with alpha.
TEST(ImageCodecs, PngReadsAsOpenImageIoReadsIt) {
  const fs::path dir = kit::test::temp_dir("codecs-png");
  for (int channels = 1; channels <= 4; ++channels) {
    const int width = 256, height = 3;
    std::vector<unsigned char> v8(static_cast<size_t>(width * height * channels));
    std::vector<uint16_t> v16(v8.size());
    for (size_t i = 0; i < v8.size(); ++i) {
      v8[i] = static_cast<unsigned char>((i * 37) % 256);
      v16[i] = static_cast<uint16_t>((i * 7919) % 65536);
    }
    const fs::path p8 = dir / ("8-" + std::to_string(channels) + ".png");
    const fs::path p16 = dir / ("16-" + std::to_string(channels) + ".png");
    write_with_openimageio(p8, width, height, channels, OIIO::TypeDesc::UINT8, v8);
    write_with_openimageio(p16, width, height, channels, OIIO::TypeDesc::UINT16, v16);
    EXPECT_TRUE(same_floats(kit::read_png(p8.string()), read_with_openimageio(p8))) << p8;
    EXPECT_TRUE(same_floats(kit::read_png(p16.string()), read_with_openimageio(p16))) << p16;
    EXPECT_TRUE(same_floats(kit::read_image(p8.string()), read_with_openimageio(p8))) << "read_image takes the same path";
    // 16 bits to 8 for textures: rounded to nearest, (v * 255 + 32767) / 65535.
    const std::vector<unsigned char> bytes = bytes_of(p16);
    const kit::Pixels8 decoded = kit::decode_png8(bytes.data(), bytes.size(), "p16", 1024);
    ASSERT_EQ(decoded.pixels.size(), v16.size());
    for (size_t i = 0; i < v16.size(); ++i)
      ASSERT_EQ(decoded.pixels[i], (static_cast<uint32_t>(v16[i]) * 255 + 32767) / 65535) << "value " << v16[i];
  }
}

// A scene's PNG colour is stored without alpha premultiplied: a texel of RGB
// (200, 50, 10) at alpha 128 (0.5) decodes to (200, 50, 10) through the scene loader,
// not the premultiplied (100, 25, 5). Here, not in test_scene_loader, because it is
// the one scene test that needs OpenImageIO linked (which costs every process start).
TEST(ImageCodecs, ScenePngColourIsNotPremultipliedByAlpha) {
  const fs::path dir = kit::test::temp_dir("codecs-unassociated-alpha");
  const fs::path gltf = kit::test::copy_scene("default", dir);
  const unsigned char texel[4] = {200, 50, 10, 128};
  const fs::path png = dir / "checker.png";  // image 0 of the default scene
  {
    std::vector<unsigned char> pixels;
    for (int i = 0; i < 4; ++i) pixels.insert(pixels.end(), texel, texel + 4);
    OIIO::ImageSpec spec(2, 2, 4, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1);  // write the bytes as they are
    auto out = OIIO::ImageOutput::create(png.string());
    ASSERT_TRUE(out && out->open(png.string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) && out->close());
  }
  {  // Witness: OpenImageIO's default read premultiplies: 2.4 (Debian 12) the stored values,
     // 200 * 128 / 255 = 100; 2.5 (Debian 13) in linear light, which gives 147.
    auto in = OIIO::ImageInput::open(png.string());
    ASSERT_TRUE(in);
    unsigned char read[16];
    ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, read));
    EXPECT_TRUE(std::abs(read[0] - 100) <= 1 || std::abs(read[0] - 147) <= 1) << int(read[0]);
  }
  const kit::Scene scene = kit::load_scene(gltf.string());
  ASSERT_NE(scene.images.at(0).what.find("checker.png"), std::string::npos) << scene.images.at(0).what;
  const kit::ImageRgba8 image = kit::decode_scene_image(scene.images.at(0));
  ASSERT_EQ(image.width, 2);
  for (size_t p = 0; p < 4; ++p)
    for (size_t c = 0; c < 4; ++c) EXPECT_EQ(image.pixels[4 * p + c], texel[c]) << "pixel " << p << " channel " << c;
}

// What the kit writes, OpenImageIO reads back with the same values: PNG as to_unorm8
// rounds them, EXR exactly (32-bit floats), grey EXR as one channel.
TEST(ImageCodecs, WrittenFilesReadTheSameInOpenImageIo) {
  const fs::path dir = kit::test::temp_dir("codecs-write");
  for (int channels = 1; channels <= 4; ++channels) {
    kit::Image image(19, 7, channels);
    for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = static_cast<float>((i * 7919) % 1021) / 1000.0f - 0.01f;
    const fs::path png = dir / ("w" + std::to_string(channels) + ".png");
    const fs::path exr = dir / ("w" + std::to_string(channels) + ".exr");
    for (kit::PngEffort effort : {kit::PngEffort::Smallest, kit::PngEffort::Fastest}) {
      kit::write_image(png.string(), image, effort);
      const kit::Image back = read_with_openimageio(png);
      ASSERT_EQ(back.pixels.size(), image.pixels.size());
      for (size_t i = 0; i < image.pixels.size(); ++i)
        ASSERT_EQ(back.pixels[i], static_cast<float>(kit::to_unorm8(image.pixels[i])) * (1.0f / 255.0f)) << i;
      EXPECT_TRUE(same_floats(kit::read_image(png.string()), back));
    }
    kit::write_image(exr.string(), image);
    EXPECT_TRUE(same_floats(read_with_openimageio(exr), image)) << exr;
    EXPECT_TRUE(same_floats(kit::read_image(exr.string()), image)) << exr;
  }
}

// EXR as OpenImageIO writes it: half floats (as kit-scenes writes its environments),
// and a data window that does not start at (0, 0).
TEST(ImageCodecs, HalfFloatExrWithAnOffsetWindowReadsAsOpenImageIoReadsIt) {
  const fs::path dir = kit::test::temp_dir("codecs-exr");
  std::vector<float> values(static_cast<size_t>(13 * 5 * 3));
  for (size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i) * 0.37f - 3.0f;
  const fs::path half = dir / "half.exr";
  write_with_openimageio(half, 13, 5, 3, OIIO::TypeDesc::HALF, values, 4, -2);
  const kit::Image ours = kit::read_exr(half.string());
  EXPECT_TRUE(same_floats(ours, read_with_openimageio(half)));
  EXPECT_EQ(ours.width, 13);
  EXPECT_EQ(ours.channels, 3);
  // The kit's own environment, read by load_environment through OpenEXR.
  const std::string sun = kit::resolve_environment("sun");
  const kit::Image theirs = read_with_openimageio(sun);
  EXPECT_TRUE(same_floats(kit::load_environment(sun), theirs));
}

// A damaged or foreign file is refused with its name and what is wrong; a PNG whose
// header claims more than the limit is refused before its rows are allocated.
TEST(ImageCodecs, BadFilesAreRefusedByName) {
  const fs::path dir = kit::test::temp_dir("codecs-bad");
  kit::Image image(64, 64, 4);
  kit::write_image((dir / "good.png").string(), image);
  std::vector<unsigned char> bytes = bytes_of(dir / "good.png");
  std::ofstream(dir / "cut.png", std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), 60);
  EXPECT_NE(error_of([&] { kit::read_image((dir / "cut.png").string()); }).find("cut.png could not be decoded"),
            std::string::npos);
  std::ofstream(dir / "text.exr") << "not an EXR";
  EXPECT_NE(error_of([&] { kit::read_image((dir / "text.exr").string()); }).find("text.exr: cannot read the EXR"),
            std::string::npos);
  EXPECT_NE(error_of([&] { kit::decode_png8(bytes.data(), bytes.size(), "image 0 ('big.png')", 32); })
                .find("image 0 ('big.png') could not be decoded"),
            std::string::npos)
      << "64 pixels a side over a limit of 32";
  EXPECT_EQ(kit::decode_png8(bytes.data(), bytes.size(), "fits", 64).width, 64);
  std::vector<float> two(static_cast<size_t>(4 * 4 * 2), 1.0f);
  auto out = OIIO::ImageOutput::create((dir / "uv.exr").string());
  OIIO::ImageSpec spec(4, 4, 2, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"U", "V"};
  ASSERT_TRUE(out->open((dir / "uv.exr").string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, two.data()) &&
              out->close());
  EXPECT_NE(error_of([&] { kit::read_exr((dir / "uv.exr").string()); }).find("channels U, V"), std::string::npos);
  EXPECT_NE(error_of([&] { kit::write_image((dir / "x.jpg").string(), image); }).find("must end in .png or .exr"),
            std::string::npos);
}

// JPEG textures and other formats go through the OpenImageIO module: the same pixels as
// OpenImageIO gives, with the size read from the header alone.
TEST(ImageCodecs, JpegAndOtherFormatsGoThroughTheOpenImageIoModule) {
  const fs::path dir = kit::test::temp_dir("codecs-module");
  std::vector<unsigned char> rgb(static_cast<size_t>(24 * 16 * 3));
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<unsigned char>((i * 13) % 251);
  write_with_openimageio(dir / "t.jpg", 24, 16, 3, OIIO::TypeDesc::UINT8, rgb);
  const std::vector<unsigned char> jpeg = bytes_of(dir / "t.jpg");
  const kit::TextureHeader header = kit::read_texture_header(jpeg.data(), jpeg.size(), "t.jpg");
  EXPECT_EQ(header.width, 24);
  EXPECT_EQ(header.height, 16);
  const kit::ImageRgba8 decoded = kit::decode_texture_image(jpeg.data(), jpeg.size(), "t.jpg");
  auto in = OIIO::ImageInput::open((dir / "t.jpg").string());
  ASSERT_TRUE(in);
  std::vector<unsigned char> theirs(rgb.size());
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, theirs.data()));
  ASSERT_EQ(decoded.pixels.size(), static_cast<size_t>(24 * 16 * 4));
  for (size_t p = 0; p < static_cast<size_t>(24 * 16); ++p) {
    for (size_t c = 0; c < 3; ++c) ASSERT_EQ(decoded.pixels[p * 4 + c], theirs[p * 3 + c]) << p;
    ASSERT_EQ(decoded.pixels[p * 4 + 3], 255);
  }
  std::vector<float> tiff(static_cast<size_t>(5 * 3 * 3), 0.5f);
  write_with_openimageio(dir / "t.tif", 5, 3, 3, OIIO::TypeDesc::FLOAT, tiff);
  EXPECT_TRUE(same_floats(kit::read_image((dir / "t.tif").string()), read_with_openimageio(dir / "t.tif")));
}

// The programs link libpng and OpenEXR, not OpenImageIO: its ~260 libraries would cost
// every start 0.2 s. The witness: the module does link it.
TEST(ImageCodecs, ProgramsDoNotLinkOpenImageIo) {
  for (const char* program : {"kit-grade", "kit-render"}) {
    std::string output;
    ASSERT_EQ(kit::test::run("ldd " + kit::test::tool(program), &output), 0) << output;
    EXPECT_EQ(output.find("libOpenImageIO"), std::string::npos) << program << ":\n" << output;
    EXPECT_NE(output.find("libpng"), std::string::npos) << program;
  }
  std::string output;
  ASSERT_EQ(kit::test::run("ldd " + (kit::test::build_dir() / "common/libkit_openimageio.so").string(), &output), 0) << output;
  EXPECT_NE(output.find("libOpenImageIO"), std::string::npos) << output;
}
