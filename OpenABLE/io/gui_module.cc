// Module libopenable_gui.so (see module_loader.h): OpenCV's highgui for Show_images.
#include <opencv2/highgui.hpp>

#include "OpenABLE/io/module_api.h"

extern "C" void openable_gui_show(const cv::Mat& frame) {
  cv::imshow("OpenABLE", frame);
  cv::waitKey(1);
}
