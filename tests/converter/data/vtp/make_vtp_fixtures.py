# Writes the .vtp fixtures of tests/converter/mesh_file_test.cpp with VTK's own writer (Debian
# python3-vtk9, VTK 9.1; not needed to build or test): one mesh (a sphere of 34 points and 64
# triangles plus a cube of 24 points and 6 quads: 58 points, 76 triangles once the quads are split)
# in every storage VTK offers. Run: /usr/bin/python3 make_vtp_fixtures.py (in this folder).
from vtkmodules.vtkFiltersSources import vtkSphereSource, vtkCubeSource
from vtkmodules.vtkFiltersCore import vtkAppendPolyData
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
from vtkmodules.vtkIOCore import vtkZLibDataCompressor, vtkLZ4DataCompressor
s = vtkSphereSource(); s.SetThetaResolution(8); s.SetPhiResolution(6); s.SetRadius(0.05)
c = vtkCubeSource(); c.SetCenter(0.2, 0, 0); c.SetXLength(0.1)
a = vtkAppendPolyData(); a.AddInputConnection(s.GetOutputPort()); a.AddInputConnection(c.GetOutputPort()); a.Update()
pd = a.GetOutput()
def w(name, mode, comp=None, header=32, block=None):
    x = vtkXMLPolyDataWriter(); x.SetInputData(pd); x.SetFileName(name)
    {'ascii': x.SetDataModeToAscii, 'binary': x.SetDataModeToBinary, 'appended': x.SetDataModeToAppended}[mode]()
    if comp is None: x.SetCompressorTypeToNone()
    elif comp == 'zlib': x.SetCompressorTypeToZLib()
    elif comp == 'lz4': x.SetCompressorTypeToLZ4()
    if header == 64: x.SetHeaderTypeToUInt64()
    if block: x.SetBlockSize(block)
    return x
w('ascii.vtp','ascii').Write()
w('binary.vtp','binary').Write()
w('binary_zlib.vtp','binary','zlib', block=256).Write()
w('binary_zlib_uint64.vtp','binary','zlib',64, block=256).Write()
x = w('appended_raw_zlib.vtp','appended','zlib', block=256); x.EncodeAppendedDataOff(); x.Write()
x = w('appended_raw.vtp','appended'); x.EncodeAppendedDataOff(); x.Write()
x = w('appended_base64_zlib.vtp','appended','zlib', block=256); x.EncodeAppendedDataOn(); x.Write()
x = w('appended_base64.vtp','appended'); x.EncodeAppendedDataOn(); x.Write()
w('binary_lz4.vtp','binary','lz4').Write()
