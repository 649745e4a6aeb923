// Module libopenable_codecs.so (see module_loader.h): OpenCV's imgcodecs, for the image formats
// the program does not decode itself (PNG and JPEG are decoded in the program: image_codec.h).
// imgcodecs loads GDAL, GDCM, OpenEXR and about 120 other libraries, which a run on PNG or JPEG
// frames no longer pays for at start-up.
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "OpenABLE/io/module_api.h"

extern "C" void openable_codecs_decode(const std::vector<unsigned char>& bytes, cv::Mat& image) {
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    image = cv::Mat();
  }
}

extern "C" void openable_codecs_read(const std::string& path, int flags, cv::Mat& image) {
  try {
    image = cv::imread(path, flags);
  } catch (const cv::Exception&) {
    image = cv::Mat();
  }
}
