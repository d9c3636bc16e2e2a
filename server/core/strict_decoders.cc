#include "server/core/strict_decoders.h"

// clang-format off
#include <cstdio>  // jpeglib.h needs FILE and size_t first
#include <jpeglib.h>
// clang-format on
#include <png.h>
#include <webp/decode.h>

#include <algorithm>
#include <csetjmp>
#include <cstring>
#include <string>
#include <vector>

#include "core/data/plain_png.h"

namespace tod::server {
namespace {

// Progressive JPEGs may have any number of scans, each a full pass over the coefficients: a
// small file with thousands of scans costs minutes. Real encoders write about ten.
constexpr int kMaxJpegScans = 256;

Status OverPixelLimit(const char* format, unsigned long width, unsigned long height,
                      long long max_pixels) {
  return Status::ResourceExhausted(
      std::string("image: ") + format + " " + std::to_string(width) + "x" + std::to_string(height) +
      " = " + std::to_string(static_cast<unsigned long long>(width) * height) +
      " pixels is over the limit of " + std::to_string(max_pixels) + " pixels");
}

bool OverLimit(unsigned long width, unsigned long height, long long max_pixels) {
  return static_cast<unsigned long long>(width) * height >
         static_cast<unsigned long long>(max_pixels);
}

// ---- JPEG ------------------------------------------------------------------------------------
//
// libjpeg reports errors by calling error_exit, which must not return; the documented way out is
// longjmp. To keep that well-defined in C++, the functions that call setjmp hold no objects with
// destructors and keep all state in JpegState (memory the caller owns), and pixel memory is
// allocated by the caller between the two phases.

struct JpegState {
  jpeg_decompress_struct cinfo{};
  jpeg_error_mgr error{};
  jpeg_progress_mgr progress{};
  std::jmp_buf jump{};
  char message[JMSG_LENGTH_MAX] = {};
  bool created = false;
};

JpegState* StateOf(j_common_ptr cinfo) { return static_cast<JpegState*>(cinfo->client_data); }

[[noreturn]] void JpegFail(j_common_ptr cinfo) {
  JpegState* state = StateOf(cinfo);
  if (state->message[0] == '\0') (*cinfo->err->format_message)(cinfo, state->message);
  std::longjmp(state->jump, 1);
}

void JpegErrorExit(j_common_ptr cinfo) { JpegFail(cinfo); }

// Level -1 is a warning: corrupt or missing data. Treated as the error it is for us.
void JpegEmitMessage(j_common_ptr cinfo, int level) {
  if (level < 0) JpegFail(cinfo);
}

void JpegOutputMessage(j_common_ptr) {}  // never write to stderr

void JpegProgress(j_common_ptr cinfo) {
  auto* decompress = reinterpret_cast<j_decompress_ptr>(cinfo);
  if (decompress->input_scan_number > kMaxJpegScans) {
    std::snprintf(StateOf(cinfo)->message, JMSG_LENGTH_MAX, "more than %d progressive scans",
                  kMaxJpegScans);
    JpegFail(cinfo);
  }
}

// Phase 1: header and output size. False on error (state->message says why).
bool JpegReadHeader(JpegState* state, const unsigned char* data, unsigned long size) {
  state->cinfo.err = jpeg_std_error(&state->error);
  state->error.error_exit = JpegErrorExit;
  state->error.emit_message = JpegEmitMessage;
  state->error.output_message = JpegOutputMessage;
  state->cinfo.client_data = state;
  if (setjmp(state->jump) != 0) return false;
  jpeg_create_decompress(&state->cinfo);
  state->created = true;
  state->progress.progress_monitor = JpegProgress;
  state->cinfo.progress = &state->progress;
  jpeg_mem_src(&state->cinfo, data, size);
  jpeg_read_header(&state->cinfo, TRUE);
  return true;
}

// Phase 2: every scanline into `rows`, then the rest of the file up to EOI, so that missing or
// extraneous data at the end is reported too.
bool JpegReadPixels(JpegState* state, unsigned char* const* rows) {
  if (setjmp(state->jump) != 0) return false;
  jpeg_start_decompress(&state->cinfo);
  while (state->cinfo.output_scanline < state->cinfo.output_height) {
    JSAMPROW row = rows[state->cinfo.output_scanline];
    jpeg_read_scanlines(&state->cinfo, &row, 1);
  }
  jpeg_finish_decompress(&state->cinfo);
  return true;
}

struct JpegStateDeleter {
  void operator()(JpegState* state) const {
    if (state->created) jpeg_destroy_decompress(&state->cinfo);
    delete state;
  }
};

// ---- PNG -------------------------------------------------------------------------------------

struct PngState {
  png_structp png = nullptr;
  png_infop info = nullptr;
  const unsigned char* data = nullptr;
  size_t size = 0;
  size_t offset = 0;
  char message[256] = {};
};

[[noreturn]] void PngFail(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngState*>(png_get_error_ptr(png));
  if (state->message[0] == '\0')
    std::snprintf(state->message, sizeof(state->message), "%s", message);
  png_longjmp(png, 1);
}

void PngError(png_structp png, png_const_charp message) { PngFail(png, message); }
void PngWarning(png_structp png, png_const_charp message) { PngFail(png, message); }

void PngRead(png_structp png, png_bytep out, size_t length) {
  auto* state = static_cast<PngState*>(png_get_io_ptr(png));
  if (length > state->size - state->offset) PngFail(png, "unexpected end of data (truncated)");
  std::memcpy(out, state->data + state->offset, length);
  state->offset += length;
}

bool PngReadHeader(PngState* state, png_uint_32* width, png_uint_32* height) {
  if (setjmp(png_jmpbuf(state->png)) != 0) return false;
  png_set_read_fn(state->png, state, PngRead);
  png_set_benign_errors(state->png, 0);            // benign errors are errors too
  png_set_chunk_malloc_max(state->png, 8u << 20);  // ancillary (e.g. zTXt) chunks
  png_read_info(state->png, state->info);
  *width = png_get_image_width(state->png, state->info);
  *height = png_get_image_height(state->png, state->info);
  // To 8-bit BGR whatever the colour type, depth, palette or transparency.
  png_set_expand(state->png);
  png_set_strip_16(state->png);
  png_set_strip_alpha(state->png);
  png_set_gray_to_rgb(state->png);
  png_set_bgr(state->png);
  png_set_interlace_handling(state->png);
  png_read_update_info(state->png, state->info);
  return true;
}

bool PngReadPixels(PngState* state, png_bytepp rows) {
  if (setjmp(png_jmpbuf(state->png)) != 0) return false;
  png_read_image(state->png, rows);
  png_read_end(state->png, nullptr);  // through IEND: trailing chunks and CRCs checked too
  return true;
}

struct PngStateDeleter {
  void operator()(PngState* state) const {
    if (state->png != nullptr) {
      png_destroy_read_struct(&state->png, state->info ? &state->info : nullptr, nullptr);
    }
    delete state;
  }
};

// libwebp's status codes as the words a client can act on.
const char* WebpStatusName(VP8StatusCode status) {
  switch (status) {
    case VP8_STATUS_OK:
      return "ok";
    case VP8_STATUS_OUT_OF_MEMORY:
      return "out of memory";
    case VP8_STATUS_INVALID_PARAM:
      return "invalid parameter";
    case VP8_STATUS_BITSTREAM_ERROR:
      return "bitstream error";
    case VP8_STATUS_UNSUPPORTED_FEATURE:
      return "unsupported feature";
    case VP8_STATUS_SUSPENDED:
      return "suspended";
    case VP8_STATUS_USER_ABORT:
      return "aborted";
    case VP8_STATUS_NOT_ENOUGH_DATA:
      return "not enough data (truncated)";
  }
  return "unknown error";
}

// Frees what libwebp allocated for the decoder's output (nothing when the output is ours).
struct WebpOutputRelease {
  WebPDecBuffer* buffer;
  ~WebpOutputRelease() { WebPFreeDecBuffer(buffer); }
};

Status Corrupt(const char* format, const char* message) {
  return Status::InvalidArgument(std::string("image: cannot decode ") + format +
                                 " (corrupt or truncated): " + message);
}

}  // namespace

Result<cv::Mat3b> DecodeJpegStrict(std::string_view bytes, long long max_pixels) {
  const std::unique_ptr<JpegState, JpegStateDeleter> state(new JpegState());
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  if (!JpegReadHeader(state.get(), data, bytes.size())) return Corrupt("JPEG", state->message);
  jpeg_decompress_struct& cinfo = state->cinfo;
  if (OverLimit(cinfo.image_width, cinfo.image_height, max_pixels)) {
    return OverPixelLimit("JPEG", cinfo.image_width, cinfo.image_height, max_pixels);
  }
  if (cinfo.jpeg_color_space == JCS_CMYK || cinfo.jpeg_color_space == JCS_YCCK) {
    return Status::InvalidArgument("image: CMYK JPEG is not supported; send RGB or greyscale");
  }
  cinfo.out_color_space = JCS_EXT_BGR;  // libjpeg-turbo converts straight to OpenCV's order
  cv::Mat3b image(static_cast<int>(cinfo.image_height), static_cast<int>(cinfo.image_width));
  std::vector<unsigned char*> rows(static_cast<size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y) rows[static_cast<size_t>(y)] = image.ptr<uchar>(y);
  if (!JpegReadPixels(state.get(), rows.data())) return Corrupt("JPEG", state->message);
  return image;
}

Result<cv::Mat3b> DecodePngStrict(std::string_view bytes, long long max_pixels) {
  // 8-bit RGB(A) frames, what cameras and datasets send, skip libpng: half the time, the same
  // pixels, the same strictness (core/data/plain_png.h).
  if (IsPlainPng(bytes)) return DecodePlainPng(bytes, max_pixels);
  const std::unique_ptr<PngState, PngStateDeleter> state(new PngState());
  state->data = reinterpret_cast<const unsigned char*>(bytes.data());
  state->size = bytes.size();
  state->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, state.get(), PngError, PngWarning);
  if (state->png == nullptr) return Status::Internal("image: cannot create a PNG reader");
  state->info = png_create_info_struct(state->png);
  if (state->info == nullptr) return Status::Internal("image: cannot create a PNG reader");
  // The header's size is checked (here and by libpng's user limits) before any row exists.
  const png_uint_32 side_limit =
      static_cast<png_uint_32>(std::min<long long>(max_pixels, PNG_USER_WIDTH_MAX));
  png_set_user_limits(state->png, side_limit, side_limit);
  png_uint_32 width = 0, height = 0;
  if (!PngReadHeader(state.get(), &width, &height)) {
    if (std::strstr(state->message, "exceeds user limit") != nullptr ||
        std::strstr(state->message, "too large") != nullptr) {
      return Status::ResourceExhausted(std::string("image: PNG is over the limit of ") +
                                       std::to_string(max_pixels) + " pixels (" + state->message +
                                       ")");
    }
    return Corrupt("PNG", state->message);
  }
  if (OverLimit(width, height, max_pixels)) {
    return OverPixelLimit("PNG", width, height, max_pixels);
  }
  if (png_get_rowbytes(state->png, state->info) != static_cast<size_t>(width) * 3) {
    return Status::InvalidArgument("image: PNG colour format could not be converted to BGR");
  }
  cv::Mat3b image(static_cast<int>(height), static_cast<int>(width));
  std::vector<png_bytep> rows(static_cast<size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y) rows[static_cast<size_t>(y)] = image.ptr<uchar>(y);
  if (!PngReadPixels(state.get(), rows.data())) return Corrupt("PNG", state->message);
  return image;
}

Result<cv::Mat3b> DecodeWebpStrict(std::string_view bytes, long long max_pixels) {
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
  WebPDecoderConfig config;
  if (!WebPInitDecoderConfig(&config)) return Status::Internal("image: libwebp version mismatch");
  // The header alone: size, alpha and animation, read before any pixel memory exists.
  if (const VP8StatusCode status = WebPGetFeatures(data, bytes.size(), &config.input);
      status != VP8_STATUS_OK) {
    return Corrupt("WebP", WebpStatusName(status));
  }
  const WebPBitstreamFeatures& features = config.input;
  if (features.has_animation) {
    return Status::InvalidArgument("image: animated WebP is not supported; send one frame");
  }
  if (features.width <= 0 || features.height <= 0) return Corrupt("WebP", "invalid size");
  const auto width = static_cast<unsigned long>(features.width);
  const auto height = static_cast<unsigned long>(features.height);
  if (OverLimit(width, height, max_pixels))
    return OverPixelLimit("WebP", width, height, max_pixels);
  // Decoded straight into our frame, in OpenCV's BGR order; alpha, if any, is dropped.
  cv::Mat3b image(features.height, features.width);
  config.output.colorspace = MODE_BGR;
  config.output.is_external_memory = 1;
  config.output.u.RGBA.rgba = image.data;
  config.output.u.RGBA.stride = static_cast<int>(image.step);
  config.output.u.RGBA.size = image.step * static_cast<size_t>(image.rows);
  const WebpOutputRelease release{&config.output};
  if (const VP8StatusCode status = WebPDecode(data, bytes.size(), &config);
      status != VP8_STATUS_OK) {
    return Corrupt("WebP", WebpStatusName(status));
  }
  return image;
}

}  // namespace tod::server
