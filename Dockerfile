# REACT3D worker image: our code with the weight-free backends by default (no torch). Build the model
# (GPU) flavour with the models extra, which brings torch from TORCH_INDEX:
#   docker build --build-arg EXTRAS=models,sim,s3 --build-arg TORCH_INDEX=https://download.pytorch.org/whl/cu124 .
FROM python:3.11-slim
ARG EXTRAS=sim,s3
ARG TORCH_INDEX=https://download.pytorch.org/whl/cpu
RUN apt-get update && apt-get install -y --no-install-recommends libusb-1.0-0 libgomp1 libgl1 libglib2.0-0 git \
    && rm -rf /var/lib/apt/lists/*
WORKDIR /opt/react3d
COPY pyproject.toml README.md ./
COPY react3d_core ./react3d_core
COPY react3d_models ./react3d_models
COPY tasks ./tasks
COPY flows ./flows
COPY deployments ./deployments
RUN pip install --no-cache-dir --extra-index-url ${TORCH_INDEX} -e ".[${EXTRAS}]"
ENV REACT3D_HOME=/opt/react3d PREFECT_SERVER_ANALYTICS_ENABLED=false
