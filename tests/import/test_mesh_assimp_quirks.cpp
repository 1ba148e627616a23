// The assimp 5.2.5 behaviours that read_obj works around, pinned down on raw assimp. If one of these
// fails after an assimp upgrade, the quirk is gone and the workaround in read_obj.cpp can go too.
#include "test_mesh_util.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

namespace cadclash::test {
namespace {

TEST(AssimpQuirks, UsemtlSplitsAGroupAndRenamesThePieces) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(mesh_data("usemtl.obj"), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  // Three groups, but five meshes, two of them named after materials.
  ASSERT_EQ(scene->mNumMeshes, 5u);
  EXPECT_STREQ(scene->mMeshes[1]->mName.C_Str(), "blue");
  EXPECT_STREQ(scene->mMeshes[2]->mName.C_Str(), "red");
}

TEST(AssimpQuirks, RecurringGroupIsASecondNode) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(mesh_data("groups.obj"), 0);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  int left = 0;
  for (unsigned i = 0; i < scene->mRootNode->mNumChildren; ++i)
    left += std::string(scene->mRootNode->mChildren[i]->mName.C_Str()) == "left";
  EXPECT_EQ(left, 2);
  EXPECT_STREQ(scene->mRootNode->mChildren[0]->mName.C_Str(), "defaultobject");
}

TEST(AssimpQuirks, TriangulateIsRightForAConcavePolygonButOnlyInFloat) {
  // Checked, as read_obj does not use it: aiProcess_Triangulate ear-clips concave polygons correctly
  // (area and winding). read_obj triangulates itself only because assimp sees vertex numbers, not
  // coordinates, to keep double precision.
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(mesh_data("concave.obj"), aiProcess_Triangulate);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  ASSERT_EQ(scene->mNumMeshes, 1u);
  const aiMesh& m = *scene->mMeshes[0];
  ASSERT_EQ(m.mNumFaces, 4u);
  double sum = 0;
  for (unsigned f = 0; f < m.mNumFaces; ++f) {
    const aiVector3D a = m.mVertices[m.mFaces[f].mIndices[0]], b = m.mVertices[m.mFaces[f].mIndices[1]],
                     c = m.mVertices[m.mFaces[f].mIndices[2]];
    const double s = 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
    EXPECT_GT(s, 0.0);
    sum += s;
  }
  EXPECT_DOUBLE_EQ(sum, 5.0);
}

TEST(AssimpQuirks, OneBadIndexLosesTheWholeFileAndShortFacesPass) {
  Assimp::Importer importer;
  EXPECT_EQ(importer.ReadFile(bad_data("index_out_of_range.obj"), 0), nullptr);
  const aiScene* scene = importer.ReadFile(bad_data("truncated.obj"), 0);
  ASSERT_NE(scene, nullptr);
  bool two_corner_face = false;
  for (unsigned i = 0; i < scene->mNumMeshes; ++i)
    for (unsigned f = 0; f < scene->mMeshes[i]->mNumFaces; ++f) two_corner_face |= scene->mMeshes[i]->mFaces[f].mNumIndices == 2;
  EXPECT_TRUE(two_corner_face);
}

}  // namespace
}  // namespace cadclash::test
