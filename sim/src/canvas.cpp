// Cairo surfaces as images and PNG files (canvas.hpp).
#include "handcentric/sim/canvas.hpp"

#include <cairo-svg.h>

#include <cstdint>
#include <cstring>

#include "handcentric/core/errors.hpp"

namespace handcentric::sim {
namespace {

constexpr int kMaxSide = 1 << 15;  // Cairo's image surfaces stop at 32767 pixels a side

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

cairo_surface_t* surface_of(int width, int height) {
  if (width < 1 || height < 1 || width >= kMaxSide || height >= kMaxSide) {
    throw InvalidArgument("canvas: a " + std::to_string(width) + " x " + std::to_string(height) +
                          " image: each side must be in [1, 32767]");
  }
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
  check_cairo(cairo_surface_status(surface), "an image surface");
  return surface;
}

const Image& checked(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3) {
    throw InvalidArgument("the image is empty or its pixel buffer has the wrong size");
  }
  return image;
}

}  // namespace

Canvas::Canvas(int width, int height)
    : width_(width),
      height_(height),
      surface_(surface_of(width, height), &cairo_surface_destroy),
      cr_(cairo_create(surface_.get()), &cairo_destroy) {
  white_page(cr_.get(), width, height);
}

Canvas::Canvas(const Image& image)
    : width_(checked(image).width),
      height_(image.height),
      surface_(surface_of(image.width, image.height), &cairo_surface_destroy),
      cr_(cairo_create(surface_.get()), &cairo_destroy) {
  cairo_surface_flush(surface_.get());
  unsigned char* data = cairo_image_surface_get_data(surface_.get());
  const int stride = cairo_image_surface_get_stride(surface_.get());
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      // RGB24: one native-endian 32-bit word per pixel, 0x00RRGGBB.
      const std::uint8_t* in = &image.rgb[(static_cast<std::size_t>(y) * width_ + x) * 3];
      const std::uint32_t word = (std::uint32_t{in[0]} << 16) | (std::uint32_t{in[1]} << 8) | in[2];
      std::memcpy(data + static_cast<std::ptrdiff_t>(y) * stride + 4 * x, &word, 4);
    }
  }
  cairo_surface_mark_dirty(surface_.get());
}

Image Canvas::image() const {
  check_cairo(cairo_status(cr_.get()), "drawing");
  cairo_surface_flush(surface_.get());
  Image image;
  image.width = width_;
  image.height = height_;
  image.rgb.resize(static_cast<std::size_t>(width_) * height_ * 3);
  const unsigned char* data = cairo_image_surface_get_data(surface_.get());
  const int stride = cairo_image_surface_get_stride(surface_.get());
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      std::uint32_t word;
      std::memcpy(&word, data + static_cast<std::ptrdiff_t>(y) * stride + 4 * x, 4);
      std::uint8_t* out = &image.rgb[(static_cast<std::size_t>(y) * width_ + x) * 3];
      out[0] = static_cast<std::uint8_t>(word >> 16);
      out[1] = static_cast<std::uint8_t>(word >> 8);
      out[2] = static_cast<std::uint8_t>(word);
    }
  }
  return image;
}

std::string Canvas::png() const {
  check_cairo(cairo_status(cr_.get()), "drawing");
  return png_of(surface_.get());
}

double text(cairo_t* cr, const std::string& s, double x, double y, double size, Align align,
            bool bold) {
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, s.c_str(), &extents);
  const double dx = align == Align::left     ? 0.0
                    : align == Align::centre ? -0.5 * extents.x_advance
                                             : -extents.x_advance;
  cairo_move_to(cr, x + dx, y);
  cairo_show_text(cr, s.c_str());
  return extents.x_advance;
}

double text_width(const std::string& s, double size, bool bold) {
  Canvas scratch(1, 1);
  cairo_select_font_face(scratch.cr(), kFont, CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(scratch.cr(), size);
  cairo_text_extents_t extents;
  cairo_text_extents(scratch.cr(), s.c_str(), &extents);
  return extents.x_advance;
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t at = s.find('\n'); at != std::string::npos; at = s.find('\n', start)) {
    lines.push_back(s.substr(start, at - start));
    start = at + 1;
  }
  lines.push_back(s.substr(start));
  return lines;
}

Image labelled(const Image& image, const std::vector<Label>& labels) {
  const Canvas canvas(image);
  set_rgb(canvas.cr(), 20, 20, 20);
  for (const Label& label : labels) text(canvas.cr(), label.text, label.x, label.y, label.size);
  return canvas.image();
}

void set_rgb(cairo_t* cr, int r, int g, int b) {
  cairo_set_source_rgb(cr, r / 255.0, g / 255.0, b / 255.0);
}

void set_grey(cairo_t* cr, double level) {
  cairo_set_source_rgb(cr, level, level, level);
}

void white_page(cairo_t* cr, int width, int height) {
  cairo_save(cr);
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_rectangle(cr, 0, 0, width, height);
  cairo_fill(cr);
  cairo_restore(cr);
}

void check_cairo(cairo_status_t status, const std::string& what) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw Error(what + " failed in Cairo: " + cairo_status_to_string(status));
}

std::string png_of(cairo_surface_t* surface) {
  cairo_surface_flush(surface);
  std::string png;
  check_cairo(cairo_surface_write_to_png_stream(surface, append, &png), "PNG encoding");
  return png;
}

std::string svg_drawing(int width, int height, const std::function<void(cairo_t*)>& draw,
                        SvgUnit unit) {
  std::string svg;
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_svg_surface_create_for_stream(append, &svg, width, height), &cairo_surface_destroy);
  check_cairo(cairo_surface_status(surface.get()), "an SVG surface");
  if (unit == SvgUnit::px) cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);
  {
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()),
                                                          &cairo_destroy);
    draw(cr.get());
    check_cairo(cairo_status(cr.get()), "drawing an SVG");
  }
  cairo_surface_finish(surface.get());
  check_cairo(cairo_surface_status(surface.get()), "SVG encoding");
  return svg;
}

}  // namespace handcentric::sim
