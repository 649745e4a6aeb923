// The structure of a ROS 1 bag, checked before rosbag_storage reads it (libopenable_rosbag.so,
// io/rosbag_module.cc). Debian's rosbag_storage trusts the lengths and positions a bag holds: on
// a damaged or made-up bag it reads past its buffers, allocates what a length announces (up to
// 4 GB) or overruns roslz4's buffer. So every record its format 2.0 reader parses is walked
// here first with reads bounded by the file: header, connections, chunk infos, each chunk
// (decompressed with libbz2 or liblz4 as rosbag_storage does), its index records, the messages
// they name and each image message (sensor_msgs/Image, CompressedImage) to its last length.
#pragma once

#include <string>

namespace openable {

// The first defect of the bag at `path` that would make rosbag_storage read it unsafely, as a
// phrase ("its chunk at byte 4105 is cut short: ..."), or "" when it can read the bag. Reads
// the file through once, one chunk at a time (chunks and record headers of at most 1 GiB and
// 16 MiB). Bags of format 2.0 only (rosbag record since 2010): another format, an encrypted bag
// and one without index (a recording cut short) are defects too.
std::string BagDefect(const std::string& path);

}  // namespace openable
