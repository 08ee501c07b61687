"""Learning: PyG datasets from Parquet, the zone-graph network, focal loss, MLflow training (planned)."""
