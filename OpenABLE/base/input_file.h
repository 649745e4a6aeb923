// The one way the readers open an input file: frames, saved maps, ROS bags, videos,
// calibrations, ground truth, trajectories, matrices, descriptor caches and configurations.
//
// Anything that is not a regular file is refused by name before a byte is read: a folder, a
// FIFO (whose read would wait for ever for a writer), a socket, a device, a symbolic link that
// leads nowhere. Every failure of the system (permission denied, an I/O error) becomes one
// InputError naming the file and the cause, never a library's own message.
#pragma once

#include <string>

namespace openable {

// What is wrong with `path` as an input file, as the words that follow its name in a message
// ("does not exist (relative to the working directory ...)", "is a folder, not a regular
// file", "is a FIFO (named pipe), not a regular file", "cannot be read (permission denied)"),
// or "" when it is a regular file that can be opened for reading. Opens nothing but
// the file itself (with O_NONBLOCK, so that a FIFO never blocks), and closes it again.
std::string InputFileProblem(const std::string& path);

// Throws InputError("<name> <problem> (<expected>)") when InputFileProblem(path) is not empty.
// `name` names the file as a message begins, e.g. `map "run.map"` or `Ground_truth "gt.txt"`;
// `expected` (may be empty) says what the file should be. For readers that hand the path to a
// library (OpenCV's video and FileStorage, rosbag, OpenImageIO).
void CheckInputFile(const std::string& path, const std::string& name,
                    const std::string& expected = "");

// The whole file, read with the same checks made on the opened file itself (no gap between the
// check and the read): one InputError like CheckInputFile's for a special file or a read error.
std::string ReadInputFile(const std::string& path, const std::string& name,
                          const std::string& expected = "");

}  // namespace openable
