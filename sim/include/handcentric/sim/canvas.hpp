#pragma once
// The one drawing stack of every figure and image file: a Cairo RGB24 surface (white, or an
// Image's pixels painted on it) with text in DejaVu Sans (Debian's fonts-dejavu-core, which
// fontconfig also falls back to; its glyphs are outlines, so an SVG of them reads the same
// everywhere), read back as an Image or encoded as PNG. Rasters that are data (camera images,
// the 2D task's drawings) come in as an Image and keep their pixels; labels go on top.
//
//   Canvas canvas(400, 300);
//   set_rgb(canvas.cr(), 20, 20, 20);
//   text(canvas.cr(), "caption", 10.0, 20.0, 13.0);
//   write_file_atomically("out.png", canvas.png());
#include <cairo.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "handcentric/sim/image.hpp"

namespace handcentric::sim {

class Canvas {
 public:
  /// A white width x height canvas. Throws InvalidArgument for a side outside [1, 2^15).
  Canvas(int width, int height);
  /// A canvas holding `image`'s pixels exactly. Throws InvalidArgument for an empty image or a
  /// pixel buffer of the wrong size.
  explicit Canvas(const Image& image);

  cairo_t* cr() const { return cr_.get(); }
  int width() const { return width_; }
  int height() const { return height_; }

  /// The pixels drawn so far. Throws Error when a drawing call failed in Cairo.
  Image image() const;
  /// The pixels drawn so far as an 8-bit RGB PNG file's bytes.
  std::string png() const;

 private:
  int width_ = 0, height_ = 0;
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface_;
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr_;
};

/// The figures' font family.
inline constexpr const char* kFont = "DejaVu Sans";

enum class Align { left, centre, right };

/// Text with its baseline at (x, y), `size` px, in the current colour; returns its advance.
double text(cairo_t* cr, const std::string& s, double x, double y, double size,
            Align align = Align::left, bool bold = false);
/// The advance of `s` at `size` px.
double text_width(const std::string& s, double size, bool bold = false);
/// `s` split at '\n'.
std::vector<std::string> lines_of(const std::string& s);

/// A line of dark grey text to write on an image: baseline at (x, y), `size` px.
struct Label {
  std::string text;
  double x = 0.0, y = 0.0;
  double size = 13.0;
};
/// `image` with `labels` written on it (every pixel the text does not touch unchanged): the
/// captions of rasters drawn by other means (OpenCV's shapes, camera images).
Image labelled(const Image& image, const std::vector<Label>& labels);

/// The source colour from 0-255 channels.
void set_rgb(cairo_t* cr, int r, int g, int b);
void set_grey(cairo_t* cr, double level);
/// The whole width x height area painted white.
void white_page(cairo_t* cr, int width, int height);

/// Throws Error "<what> failed in Cairo: <status>" unless `status` is success.
void check_cairo(cairo_status_t status, const std::string& what);
/// A surface's pixels encoded as PNG (RGB24: 8-bit RGB).
std::string png_of(cairo_surface_t* surface);
/// The unit of an SVG document's width and height (its drawing is in user units either way):
/// Cairo's default, points, or pixels, for a picture shown at the size it was drawn.
enum class SvgUnit { pt, px };
/// The SVG document of a width x height drawing made by `draw` (text as glyph outlines).
std::string svg_drawing(int width, int height, const std::function<void(cairo_t*)>& draw,
                        SvgUnit unit = SvgUnit::pt);

}  // namespace handcentric::sim
