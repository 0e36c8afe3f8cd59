#pragma once
// PNG encoding of 8-bit RGB pixels (ISO/IEC 15948): the bytes of a file write_png (draw.hpp)
// writes. Written on zlib rather than OpenCV's imgcodecs, whose ~130 shared libraries (DICOM,
// GDAL, OpenEXR, ...) every program linking it loaded at each start: 0.2 s of CPU per
// `handcentric` command, 0.45 s under AddressSanitizer.
#include <cstdint>
#include <string>

namespace handcentric::sim {

/// The PNG file of a width x height image, rows top to bottom, 3 bytes (R, G, B) per pixel:
/// colour type 2, bit depth 8, no interlace; each row filtered with the filter of the five
/// whose output has the smallest sum of absolute values (the specification's heuristic), then
/// one zlib stream at the default level. The same pixels give the same bytes.
/// Throws InvalidArgument for a size outside [1, 2^24) per side or a buffer of another length.
std::string encode_png(const std::uint8_t* rgb, std::size_t size, int width, int height);

/// The prediction of filter type `type` (0 none, 1 sub, 2 up, 3 average, 4 Paeth; section 9)
/// for a byte from the bytes left of it, above it and above-left.
int png_prediction(int type, int left, int up, int up_left);
using PngPredictor = int (*)(int type, int left, int up, int up_left);
/// encode_png with the filters' predictions from `predict` rather than png_prediction: the
/// tests plant a wrong one (tests/sim/test_png.cpp) and see a decoder's pixels differ.
std::string encode_png_predicting(const std::uint8_t* rgb, std::size_t size, int width, int height,
                                  PngPredictor predict);

}  // namespace handcentric::sim
