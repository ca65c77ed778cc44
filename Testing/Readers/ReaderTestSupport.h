// Shared by the VTK tests of the readers: catching vtkErrorMacro / vtkWarningMacro text, reading a reader's
// output with the catcher attached, and whole files as bytes.
#ifndef meshfree_ReaderTestSupport_h
#define meshfree_ReaderTestSupport_h

#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <fstream>
#include <iterator>
#include <string>

namespace meshfree_test
{
// Catches the messages of vtkErrorMacro / vtkWarningMacro so that the test can check their text.
class MessageCatcher : public vtkCommand
{
public:
  static MessageCatcher* New() { return new MessageCatcher; }
  void Execute(vtkObject*, unsigned long event, void* data) override
  {
    (event == vtkCommand::ErrorEvent ? this->Errors : this->Warnings) += static_cast<const char*>(data);
  }
  std::string Errors, Warnings;
};

/// The output of a reader of FileName/KeepInvalidPoints (the PCD and XYZ readers), its messages in catcher.
template <class Reader>
vtkSmartPointer<vtkPolyData> Read(const std::string& path, MessageCatcher* catcher, bool keepInvalid = false)
{
  vtkNew<Reader> reader;
  reader->SetFileName(path.c_str());
  reader->SetKeepInvalidPoints(keepInvalid);
  reader->AddObserver(vtkCommand::ErrorEvent, catcher);
  reader->AddObserver(vtkCommand::WarningEvent, catcher);
  reader->Update();
  return reader->GetOutput();
}

inline std::string ReadBytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void WriteText(const std::string& path, const std::string& text)
{
  std::ofstream(path, std::ios::binary) << text;
}
} // namespace meshfree_test

#endif
