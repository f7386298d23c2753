// Writing files with VTK: errors, temporary files, .vtu files of unstructured grids.
#include "mpm/post/vtk/vtk_files.hpp"

#include <unistd.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnstructuredGrid.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "mpm/core/error.hpp"

namespace mpm::vtk_internal {

namespace {

/// Trims VTK's "ERROR: In file.cxx, line N\nvtkClass (0x...): text" to its last line.
std::string vtk_message(const std::string& m) {
  std::string s = m;
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  const auto nl = s.rfind('\n');
  if (nl != std::string::npos) s = s.substr(nl + 1);
  const auto colon = s.find("): ");
  if (colon != std::string::npos) s = s.substr(colon + 3);
  return s;
}

/// Adds a one-value field-data array.
template <class A, class V>
void add_field_value(vtkFieldData* fd, const char* name, V value) {
  vtkNew<A> a;
  a->SetName(name);
  a->SetNumberOfTuples(1);
  a->SetValue(0, value);
  fd->AddArray(a);
}

}  // namespace

std::string writer_failure(const ErrorCatcher& own, unsigned long code,
                           const ErrorCatcher& pipeline, const std::string& written,
                           const std::string& path) {
  if (code > 0 && code < vtkErrorCode::FirstVTKErrorCode)  // a system errno
    return std::strerror(int(code));
  if (!own.message.empty()) {
    std::string m = vtk_message(own.message);
    for (auto at = m.find(written); !written.empty() && at != std::string::npos;
         at = m.find(written))
      m.replace(at, written.size(), path);
    return m;
  }
  switch (code) {
    case vtkErrorCode::OutOfDiskSpaceError:
      return "out of disk space";
    case vtkErrorCode::CannotOpenFileError:
      return "cannot open the file";
    case vtkErrorCode::NoFileNameError:
      return "no file name";
    case vtkErrorCode::NoError:
      break;
    default:
      return "VTK error code " + std::to_string(code);
  }
  if (!pipeline.message.empty()) return "the VTK pipeline failed";
  return "the VTK writer failed";
}

FileTarget::FileTarget(std::string path) : path_(std::move(path)) {
  std::error_code ec;
  if (std::filesystem::is_directory(path_, ec))  // VTK's writers spin on a directory
    throw InputError(path_, "is a directory; expected the name of a file to write");
  const auto st = std::filesystem::symlink_status(path_, ec);
  const bool special = !ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st);
  write_path_ = special ? path_ : path_ + ".tmp" + std::to_string(::getpid());
}

FileTarget::~FileTarget() {
  if (!committed_ && write_path_ != path_) {
    std::error_code ec;
    std::filesystem::remove(write_path_, ec);
  }
}

void FileTarget::commit() {
  if (write_path_ != path_ && std::rename(write_path_.c_str(), path_.c_str()) != 0)
    throw IoError("cannot write " + path_ + ": " + std::strerror(errno));
  committed_ = true;
}

/// Time fields and the write of an unstructured grid as an appended, zlib-compressed .vtu,
/// through a temporary file committed only when the write succeeded: "TIME" (VisIt convention,
/// shown by ParaView's Annotate Time Filter), "TimeValue" (what VTK's and ParaView's XML readers
/// use as the time of a lone file or file series), and the step as "CYCLE".
void write_unstructured(vtkUnstructuredGrid* grid, double time, std::int64_t step,
                        const std::string& path) {
  vtkFieldData* fd = grid->GetFieldData();
  add_field_value<vtkDoubleArray>(fd, "TIME", time);
  add_field_value<vtkDoubleArray>(fd, "TimeValue", time);
  add_field_value<vtkTypeInt64Array>(fd, "CYCLE", vtkTypeInt64(step));

  FileTarget target(path);
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  vtkNew<ErrorCatcher> errors, pipeline_errors;
  writer->AddObserver(vtkCommand::ErrorEvent, errors);
  writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, pipeline_errors);
  writer->SetInputData(grid);
  writer->SetFileName(target.write_path().c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();  // raw binary, not base64
  writer->SetCompressorTypeToZLib();
  writer->SetCompressionLevel(1);   // fastest zlib: 4x smaller here, level 5 takes 3x as long
  writer->SetHeaderTypeToUInt64();  // blocks and arrays beyond 4 GiB
  writer->SetIdTypeToInt64();
  const int ok = writer->Write();
  if (!ok || writer->GetErrorCode() != 0 || !errors->message.empty() ||
      !pipeline_errors->message.empty())
    throw IoError("cannot write " + path + ": " +
                  writer_failure(*errors, writer->GetErrorCode(), *pipeline_errors,
                                 target.write_path(), path));
  target.commit();
}

/// Renders the window once and writes its back buffer as a PNG through a FileTarget.
void write_png(vtkRenderWindow* window, const std::string& path) {
  [[maybe_unused]] const GraphicsStack graphics;
  // The filter renders the window once (its ShouldRerender) and reads the back buffer.
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  FileTarget target(path);
  vtkNew<vtkPNGWriter> png;
  vtkNew<ErrorCatcher> png_errors, pipeline_errors;
  png->AddObserver(vtkCommand::ErrorEvent, png_errors);
  png->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, pipeline_errors);
  png->SetInputConnection(grab->GetOutputPort());
  png->SetFileName(target.write_path().c_str());
  png->Write();
  if (png->GetErrorCode() != 0 || !png_errors->message.empty() || !pipeline_errors->message.empty())
    throw IoError("cannot write " + path + ": " +
                  writer_failure(*png_errors, png->GetErrorCode(), *pipeline_errors,
                                 target.write_path(), path));
  target.commit();
}

}  // namespace mpm::vtk_internal
