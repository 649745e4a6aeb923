// The structure of a ROS 1 bag, checked before rosbag_storage reads it (libopenable_rosbag.so,
// io/rosbag_module.cc). Debian's rosbag_storage trusts the lengths and positions a bag holds:
// on a damaged or made-up bag it reads past its buffers (ros::Header::parse takes a field's
// length as it is written, a message is read at whatever offset the index names), allocates
// what a length announces (up to 4 GB for a record header, a chunk, or an image's data when
// the message is deserialised), lets roslz4 write a block longer than its buffer, or throws
// std::runtime_error for a time whose nanoseconds overflow. So every record that its reader of
// format 2.0 parses is walked here first, with reads bounded by the file: the file header, the
// connection records, the chunk infos, each chunk (decompressed as rosbag_storage does: bz2 with
// libbz2, lz4 frames as roslz4 writes them, with liblz4) and its index records, the message
// record each index entry names, and each image message (sensor_msgs/Image and
// CompressedImage) to its last length.
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
