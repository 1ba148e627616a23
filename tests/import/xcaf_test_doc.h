// An XCAF document a test fills with named shapes and occurrences, then writes as a STEP file the
// way KiCad's exporter and other OCCT-based tools write assemblies (STEPCAFControl_Writer, names on).
#pragma once

#include "../test_temp.h"

#include <STEPCAFControl_Writer.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <gtest/gtest.h>

#include <string>

namespace cadclash::testing {

class XcafTestDoc {
 public:
  XcafTestDoc() {
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc_);
    tool_ = XCAFDoc_DocumentTool::ShapeTool(doc_->Main());
  }
  ~XcafTestDoc() { XCAFApp_Application::GetApplication()->Close(doc_); }
  XcafTestDoc(const XcafTestDoc&) = delete;
  XcafTestDoc& operator=(const XcafTestDoc&) = delete;

  const Handle(XCAFDoc_ShapeTool)& tool() const { return tool_; }

  // Names a label (a shape, an assembly or an occurrence) and returns it.
  static TDF_Label name(const TDF_Label& l, const char* n) {
    TDataStd_Name::Set(l, TCollection_ExtendedString(n));
    return l;
  }

  // Writes the document to `file_name` in the scratch folder; returns its path.
  std::string write_step(const std::string& file_name) {
    tool_->UpdateAssemblies();
    const std::string path = scratch_dir() + "/" + file_name;
    STEPCAFControl_Writer writer;
    writer.SetNameMode(Standard_True);
    EXPECT_TRUE(writer.Transfer(doc_, STEPControl_AsIs));
    EXPECT_EQ(writer.Write(path.c_str()), IFSelect_RetDone);
    return path;
  }

 private:
  Handle(TDocStd_Document) doc_;
  Handle(XCAFDoc_ShapeTool) tool_;
};

}  // namespace cadclash::testing
