// The entry points of the modules loaded at run time (module_loader.h). A module and the
// program that loads it come from the same build, so C++ types cross the boundary.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/io/frame_source.h"

// libopenable_oiio.so: decodes `path` with OpenImageIO into the frame format of
// frame_source.h. Throws InputError naming the file.
extern "C" void openable_oiio_read(const std::string& path, cv::Mat& frame);
using OpenableOiioRead = void (*)(const std::string&, cv::Mat&);
// The same on the bytes of an image file held in memory; `name` names it in messages and its
// extension, if any, is OpenImageIO's first guess of the format.
extern "C" void openable_oiio_read_memory(const std::string& bytes, const std::string& name,
                                          cv::Mat& frame);
using OpenableOiioReadMemory = void (*)(const std::string&, const std::string&, cv::Mat&);

// libopenable_codecs.so: OpenCV's imgcodecs (cv::imdecode with IMREAD_UNCHANGED) for the
// formats the program does not decode itself (PGM/PPM, BMP); an empty `image` when OpenCV
// cannot decode the bytes.
extern "C" void openable_codecs_decode(const std::vector<unsigned char>& bytes, cv::Mat& image);
using OpenableCodecsDecode = void (*)(const std::vector<unsigned char>&, cv::Mat&);
// cv::imread(path, flags); an empty `image` when OpenCV cannot read the file.
extern "C" void openable_codecs_read(const std::string& path, int flags, cv::Mat& image);
using OpenableCodecsRead = void (*)(const std::string&, int, cv::Mat&);

// libopenable_video.so: the frames [first, last) of a video (see OpenVideo).
extern "C" void openable_video_open(const std::string& path, int first, int last,
                                    std::unique_ptr<openable::FrameSource>& source);
using OpenableVideoOpen = void (*)(const std::string&, int, int,
                                   std::unique_ptr<openable::FrameSource>&);

// libopenable_rosbag.so: the messages [first, last) of an image topic of a ROS 1 bag (see
// OpenBag); `key` and `topic_key` name the Config.txt keys in messages.
extern "C" void openable_rosbag_open(const std::string& path, const std::string& topic, int first,
                                     int last, const std::string& key, const std::string& topic_key,
                                     std::unique_ptr<openable::FrameSource>& source);
using OpenableRosbagOpen = void (*)(const std::string&, const std::string&, int, int,
                                    const std::string&, const std::string&,
                                    std::unique_ptr<openable::FrameSource>&);

// libopenable_gui.so: shows a frame in the window "OpenABLE" (Show_images 1).
extern "C" void openable_gui_show(const cv::Mat& frame);
using OpenableGuiShow = void (*)(const cv::Mat&);

// libopenable_mpi.so: Open MPI for a run spread over the processes mpirun started
// (OpenABLE/cluster/cluster.h). Built only when CMake finds MPI. Every call but init and abort is
// collective: each process of the world makes it, in the same order.
// MPI_Init (with MPI_THREAD_FUNNELED: only the calling thread talks to MPI) and this process's
// rank and the world's size.
extern "C" void openable_mpi_init(int* rank, int* size);
using OpenableMpiInit = void (*)(int*, int*);
extern "C" void openable_mpi_finalize();
using OpenableMpiFinalize = void (*)();
// MPI_Abort(MPI_COMM_WORLD, code): ends every process of the run.
extern "C" void openable_mpi_abort(int code);
using OpenableMpiAbort = void (*)(int);
// The bytes of every process in rank order, on rank `root` only (root -1: on every process);
// `sizes` receives each process's byte count there. Any size (sent in pieces below 2^31).
extern "C" void openable_mpi_gather(const std::vector<char>& mine, int root, std::vector<char>& all,
                                    std::vector<std::int64_t>& sizes);
using OpenableMpiGather = void (*)(const std::vector<char>&, int, std::vector<char>&,
                                   std::vector<std::int64_t>&);
// The `bytes` at `mine` of every process, in rank order, into `into` on process 0, which holds
// exactly the sum of the processes' counts, `capacity` (returns false, receiving nothing, when
// the counts do not add up to it); the other processes pass nullptr. Collective.
extern "C" bool openable_mpi_gather_into(const char* mine, std::int64_t bytes, char* into,
                                         std::int64_t capacity);
using OpenableMpiGatherInto = bool (*)(const char*, std::int64_t, char*, std::int64_t);
// The largest of every process's `value`, on every process.
extern "C" double openable_mpi_max(double value);
using OpenableMpiMax = double (*)(double);
