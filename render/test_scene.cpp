#include "render/test_scene.hpp"

#include <cmath>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "render/gl_context.hpp"

namespace furrow::render {

namespace {
constexpr double kDiskRadiusWorld = 0.5;  // view spans y in [-1, 1]
constexpr int kCaptionFontPx = 20;
}  // namespace

TestSceneLayout test_scene_layout(int width, int height) {
  TestSceneLayout l;
  l.disk_center_x_px = 0.5 * width;
  l.disk_center_y_px = 0.5 * height;
  l.disk_radius_px = kDiskRadiusWorld * 0.5 * height;  // parallel scale 1 -> half height is 1 unit
  l.caption_x0 = 0;
  l.caption_x1 = width;
  l.caption_y0 = height - 2 * kCaptionFontPx;
  l.caption_y1 = height;
  return l;
}

RgbImage render_test_scene(int width, int height) {
  const TestSceneLayout layout = test_scene_layout(width, height);
  OffscreenWindow win(width, height);

  // Disk as a triangle fan of 128 segments.
  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> polys;
  const int n = 128;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * k / n;
    pts->InsertNextPoint(kDiskRadiusWorld * std::cos(a), kDiskRadiusWorld * std::sin(a), 0.0);
  }
  pts->InsertNextPoint(0, 0, 0);
  for (int k = 0; k < n; ++k) {
    const vtkIdType tri[3] = {n, k, (k + 1) % n};
    polys->InsertNextCell(3, tri);
  }
  vtkNew<vtkPolyData> disk;
  disk->SetPoints(pts);
  disk->SetPolys(polys);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(disk);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  // Unlit so the colour on screen is exactly the colour asked for.
  actor->GetProperty()->SetColor(layout.disk[0] / 255.0, layout.disk[1] / 255.0, layout.disk[2] / 255.0);
  actor->GetProperty()->LightingOff();

  vtkNew<vtkTextActor> caption;
  caption->SetInput("Furrow headless render check");
  caption->GetTextProperty()->SetFontSize(kCaptionFontPx);
  caption->GetTextProperty()->SetColor(1, 1, 1);
  caption->SetDisplayPosition(kCaptionFontPx / 2, kCaptionFontPx / 2);

  vtkNew<vtkRenderer> ren;
  ren->SetBackground(layout.background[0] / 255.0, layout.background[1] / 255.0, layout.background[2] / 255.0);
  ren->AddActor(actor);
  ren->AddActor2D(caption);
  vtkCamera* cam = ren->GetActiveCamera();
  cam->ParallelProjectionOn();
  cam->SetPosition(0, 0, 10);
  cam->SetFocalPoint(0, 0, 0);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(1.0);
  ren->ResetCameraClippingRange();
  win.window()->AddRenderer(ren);
  return win.capture();
}

}  // namespace furrow::render
