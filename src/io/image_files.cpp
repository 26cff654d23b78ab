// TIFF, PNG and JPEG through the format libraries themselves (libtiff, libpng, libjpeg): a general
// image library would load video, GIS and computer-vision libraries into every run.
#include <csetjmp>
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include <jpeglib.h>  // needs size_t and FILE declared first
#include <png.h>
#include <tiffio.h>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& why) { throw InputError(file.string(), 0, "cannot write: " + why); }

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

File openForWriting(const std::filesystem::path& file) {
  File f(std::fopen(file.c_str(), "wb"));
  if (!f) fail(file, "cannot open for writing");
  return f;
}

// libtiff reports through global handlers; the last message is kept for the error.
thread_local std::string tiff_message;
void tiffHandler(const char* module, const char* fmt, va_list ap) {
  char buf[512];
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  tiff_message = std::string(module ? module : "libtiff") + ": " + buf;
}

}  // namespace

void writeTiff(const std::filesystem::path& file, const VolumeView& v) {
  const VolumeGrid& g = *v.grid;
  TIFFSetErrorHandler(tiffHandler);
  TIFFSetWarningHandler(nullptr);
  tiff_message.clear();
  std::unique_ptr<TIFF, void (*)(TIFF*)> tif(TIFFOpen(file.c_str(), "w"), [](TIFF* t) {
    if (t) TIFFClose(t);
  });
  if (!tif) fail(file, tiff_message.empty() ? "cannot open for writing" : tiff_message);
  const std::size_t bytes = voxelBytes(v.type);
  const int format = v.type == VoxelType::Float32 ? SAMPLEFORMAT_IEEEFP : v.type == VoxelType::Int16 ? SAMPLEFORMAT_INT : SAMPLEFORMAT_UINT;
  const std::size_t row = std::size_t(g.dims[0]) * bytes, slice = row * std::size_t(g.dims[1]);
  // Strips of about 64 KiB: small enough to stream, large enough to compress well.
  const std::uint32_t rows_per_strip =
      std::uint32_t(std::max<std::size_t>(1, std::min<std::size_t>(g.dims[1], 65536 / std::max<std::size_t>(row, 1))));
  for (std::int32_t z = 0; z < g.dims[2]; ++z) {
    TIFF* t = tif.get();
    TIFFSetField(t, TIFFTAG_IMAGEWIDTH, std::uint32_t(g.dims[0]));
    TIFFSetField(t, TIFFTAG_IMAGELENGTH, std::uint32_t(g.dims[1]));
    TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1);
    TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, int(8 * bytes));
    TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, format);
    TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK);
    TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE);
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, rows_per_strip);
    TIFFSetField(t, TIFFTAG_RESOLUTIONUNIT, RESUNIT_CENTIMETER);
    TIFFSetField(t, TIFFTAG_XRESOLUTION, float(10.0 / g.spacing_mm.x));  // pixels per cm
    TIFFSetField(t, TIFFTAG_YRESOLUTION, float(10.0 / g.spacing_mm.y));
    TIFFSetField(t, TIFFTAG_IMAGEDESCRIPTION, v.description.c_str());
    TIFFSetField(t, TIFFTAG_SUBFILETYPE, FILETYPE_PAGE);
    TIFFSetField(t, TIFFTAG_PAGENUMBER, std::uint16_t(z), std::uint16_t(g.dims[2]));
    const char* base = static_cast<const char*>(v.data) + std::size_t(z) * slice;
    for (std::uint32_t y = 0, strip = 0; y < std::uint32_t(g.dims[1]); y += rows_per_strip, ++strip) {
      const std::uint32_t n = std::min<std::uint32_t>(rows_per_strip, std::uint32_t(g.dims[1]) - y);
      if (TIFFWriteEncodedStrip(t, strip, const_cast<char*>(base + y * row), tmsize_t(n * row)) < 0) fail(file, tiff_message);
    }
    if (!TIFFWriteDirectory(t)) fail(file, tiff_message);
  }
}

void writePng(const std::filesystem::path& file, const Image8& image) {
  File f = openForWriting(file);
  writePng(f.get(), file, image);
}

void writePng(std::FILE* out, const std::filesystem::path& file, const Image8& image) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    fail(file, "libpng could not start");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    fail(file, "libpng failed (disk full?)");
  }
  png_init_io(png, out);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, image.channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  const std::size_t stride = std::size_t(image.width) * image.channels;
  for (int y = 0; y < image.height; ++y) png_write_row(png, image.pixels.data() + std::size_t(y) * stride);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(out) != 0 || std::ferror(out)) fail(file, "write error (disk full?)");
}

std::string encodePng(const Image8& image) {
  char* buf = nullptr;
  std::size_t size = 0;
  std::FILE* f = open_memstream(&buf, &size);
  if (!f) throw std::runtime_error("cannot open a memory stream for a PNG");
  try {
    writePng(f, "image", image);
  } catch (...) {
    std::fclose(f);
    std::free(buf);
    throw;
  }
  std::fclose(f);
  std::string out(buf, size);
  std::free(buf);
  return out;
}

namespace {
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};
void jpegExit(j_common_ptr c) {
  auto* e = reinterpret_cast<JpegError*>(c->err);
  (*c->err->format_message)(c, e->message);
  std::longjmp(e->jump, 1);
}
}  // namespace

void writeJpeg(const std::filesystem::path& file, const Image8& image, int quality) {
  File f = openForWriting(file);
  jpeg_compress_struct c;
  JpegError err;
  c.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = jpegExit;
  if (setjmp(err.jump)) {
    jpeg_destroy_compress(&c);
    fail(file, err.message);
  }
  jpeg_create_compress(&c);
  jpeg_stdio_dest(&c, f.get());
  c.image_width = JDIMENSION(image.width);
  c.image_height = JDIMENSION(image.height);
  c.input_components = image.channels;
  c.in_color_space = image.channels == 3 ? JCS_RGB : JCS_GRAYSCALE;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, quality, TRUE);
  jpeg_start_compress(&c, TRUE);
  const std::size_t stride = std::size_t(image.width) * image.channels;
  while (c.next_scanline < c.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(image.pixels.data() + c.next_scanline * stride);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  if (std::fflush(f.get()) != 0 || std::ferror(f.get())) fail(file, "write error (disk full?)");
}

}  // namespace angiosynth
