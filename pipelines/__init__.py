"""DVC stage entry points and Dask orchestration (thin: the work lives in zonegraph/training/eval)."""
