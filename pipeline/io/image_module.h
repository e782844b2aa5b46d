// OpenImageIO, loaded when an image file is first read or written. Debian's OpenImageIO brings about 260
// shared libraries (OpenCV, GDAL, FFmpeg, GStreamer...) whose loading and relocation took 0.39-0.47 s of
// every start of `sylva`, also of `sylva --help` and of commands that touch no image; the program now links
// none of them, and this door loads the module libsylva_oiio.so (pipeline/oiio/oiio_module.cpp, the only code
// that includes OpenImageIO's headers) with dlopen on first use. image_io, dem_io, env_map_io and the study's
// reader go through it.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace sylva::image_module {

// How a file stores its samples (readers normalize integer types to [0, 1] when reading as float).
enum class SampleType : int { UInt8, UInt16, Int16, UInt32, Int32, Half, Float, Other };

// What a float file's colour channels hold, named in its header by the module (OpenEXR: the chromaticities
// of the primaries and white, and the colour interop ID). Sylva's float pictures are scene-linear Rec.709.
enum class ColorSpace : int { Unnamed, LinearRec709 };

struct Info {
    int width = 0, height = 0, channels = 0;
    int alphaChannel = -1;               // as the file's header says (-1: none named)
    SampleType type = SampleType::Other;
    std::vector<std::string> channelNames;
};

// What the module exports (its one symbol, sylvaImageModule, returns it). Nothing throws across it:
// failures return null / 0 with OpenImageIO's message in *error.
struct Table {
    int abi;
    void* (*openRead)(const char* path, int unassociatedAlpha, Info* info, std::string* error);
    int (*readFloat)(void* input, int channels, float* out, std::string* error);   // the first `channels` channels
    void (*closeRead)(void* input);
    // names: null for the format's defaults, else `channels` names (alpha and depth then unnamed);
    // alphaChannel >= 0 marks that channel straight (unassociated) alpha. The message says which step
    // failed: "no image writer for this extension (...)" or "cannot write image (...)". colorSpace: named in the header.
    // attributes: attributeCount (name, value) string pairs for the header, 2 x attributeCount strings (null when none).
    void* (*openWrite)(const char* path, int width, int height, int channels, const std::string* names, SampleType stored,
                       int alphaChannel, ColorSpace colorSpace, const std::string* attributes, int attributeCount, std::string* error);
    int (*writeImage)(void* output, const float* data, std::string* error);             // every row
    int (*writeRows)(void* output, int y0, int y1, const float* data, std::string* error);
    int (*closeWrite)(void* output, std::string* error);   // frees the output, also when closing fails
};
constexpr int kAbi = 3;

// The module, loaded on the first call (thread-safe). Throws Error when it cannot be found or loaded:
// SYLVA_IMAGE_MODULE names it, else it is looked for beside the executable, then installed (BINDIR/../LIBDIR/
// sylva), then at the places addSearchPath gave, then where the build put it.
const Table& table();

// One more place to look for the module file, after the executable's: a library loaded into another program (the
// Python module) names the installed module relative to its own file.
void addSearchPath(const std::string& path);

// Throws table()'s Error at once when no module file exists where table() looks (nothing is loaded): for
// a command that writes an image at its end, so a missing module fails it before its work. The module is
// not loaded early on a thread: beside the loader's 0.35 s the scene's asset loading and build of sylva
// render ran 0.3-0.5 s longer (the dynamic loader's lock, which thread creation and every dlopen take),
// and the render's wall time grew from 2.03 to 2.61 s (docs/PERFORMANCE.md "Start").
void requireFindable();

// An image file open for reading.
class Reader {
public:
    // Null with the module's message in `error` when the file cannot be opened as an image.
    static std::unique_ptr<Reader> open(const std::string& path, bool unassociatedAlpha, std::string& error);
    ~Reader();
    Reader(const Reader&) = delete;
    Reader& operator=(const Reader&) = delete;
    const Info& info() const { return m_info; }
    // Every pixel's first `channels` channels as float, interleaved, top row first; false with the message.
    bool read(int channels, std::vector<float>& out, std::string& error);

private:
    Reader() = default;
    const Table* m_table = nullptr;
    void* m_input = nullptr;
    Info m_info;
};

// An image file open for writing (the format follows the path's extension).
class Writer {
public:
    // attributes: (name, value) pairs for the header, name0, value0, name1, value1, ... (string attributes:
    // OpenEXR's header keys, e.g. Cryptomatte's "cryptomatte/<key>/manifest").
    static std::unique_ptr<Writer> open(const std::string& path, int width, int height, int channels, const std::vector<std::string>* names,
                                        SampleType stored, int alphaChannel, ColorSpace colorSpace, std::string& error,
                                        const std::vector<std::string>* attributes = nullptr);
    ~Writer();   // closes a file not yet closed (its caller removes it)
    Writer(const Writer&) = delete;
    Writer& operator=(const Writer&) = delete;
    bool writeImage(const float* data, std::string& error);
    bool writeRows(int y0, int y1, const float* data, std::string& error);
    bool close(std::string& error);

private:
    Writer() = default;
    const Table* m_table = nullptr;
    void* m_output = nullptr;
};

} // namespace sylva::image_module
