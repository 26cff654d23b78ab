# Sourced by the benchmarks that image the 4000-terminal CCO sphere on 256³ voxels:
# sphere256 DIR writes DIR/sphere_256.toml (examples/cco_sphere_3d.toml at 0.225 mm, NIfTI only).
sphere256() {
  sed -e 's|^voxel_size = "0.3 mm".*|voxel_size = "0.2250 mm"|' -e 's|^formats = .*|formats = ["nifti"]|' \
      examples/cco_sphere_3d.toml > "$1/sphere_256.toml"
}
