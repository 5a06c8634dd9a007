"""Reading and writing frames (xarray/Zarr) and tables (Parquet)."""
