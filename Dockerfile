# Multi-stage: build with the same setup script as developers and CI; run as a non-root user
# from an image that holds effectd, the libraries it loads and Mesa's software renderer only.
#   podman build --isolation=chroot -t effectd .       (or docker build -t effectd .)
# The default target, edge, puts nginx in front of effectd in the one container (publish 8080;
# the admin port 9090 is for probes and Prometheus). --target runtime is effectd alone, for a
# deployment that brings its own proxy: deploy/k8s runs it beside an nginx sidecar.
# scripts/test-image.sh builds it with a binary built on the host instead (--build-arg
# PREBUILT=1: the binary staged at build/image/effectd; nothing is installed or compiled).
FROM debian:bookworm AS build
ARG PREBUILT=0
WORKDIR /src
COPY scripts/setup.sh scripts/setup.sh
RUN [ "$PREBUILT" = 1 ] || { scripts/setup.sh && rm -rf /var/lib/apt/lists/*; }
COPY . .
# setup.sh again now that the tree is here: it installs the playground's three.js (npm ci, pinned
# and integrity-checked), which the build embeds.
RUN if [ "$PREBUILT" = 1 ]; then install -D -m 755 build/image/effectd /build/server/effectd; \
    else scripts/setup.sh && BUILD_DIR=/build scripts/build.sh -DEFFECTD_TESTS=OFF -DEFFECTD_BENCH=OFF; fi

# Every package effectd's libraries come from (OpenImageIO alone pulls GDAL, OpenVDB,
# FFmpeg ...): a complete system to collect the runtime from, and `--target full` for
# debugging with a shell and apt.
FROM debian:bookworm-slim AS full
RUN apt-get update -qq \
 && apt-get install -y -qq --no-install-recommends \
      libcpp-httplib0.11 libopenimageio2.4 libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri curl ca-certificates \
 && rm -rf /var/lib/apt/lists/* \
 && useradd --system --uid 10001 --no-create-home effectd
COPY --from=build /build/server/effectd /usr/local/bin/effectd

FROM full AS closure
COPY deploy/image/closure.sh /usr/local/bin/closure.sh
RUN closure.sh /runtime /usr/local/bin/effectd /usr/bin/curl

FROM scratch AS runtime
COPY --from=closure /runtime /
USER 10001
EXPOSE 8080
# XDG_CACHE_HOME: Mesa's shader cache on the writable /tmp (the root filesystem is read-only).
ENV EFFECTD_HOST=0.0.0.0 EFFECTD_PORT=8080 LP_NUM_THREADS=2 XDG_CACHE_HOME=/tmp/cache
HEALTHCHECK --interval=10s --timeout=3s --retries=3 CMD ["/usr/bin/curl", "-fsS", "http://127.0.0.1:8080/healthz"]
ENTRYPOINT ["/usr/local/bin/effectd"]
CMD ["serve"]

# The edge: the runtime with nginx and bash added, effectd on loopback behind nginx
# (deploy/image/edge.sh, deploy/nginx/pod.conf and edge.conf; docs/serving.md, "The edge").
FROM full AS edge-closure
RUN apt-get update -qq && apt-get install -y -qq --no-install-recommends nginx-light && rm -rf /var/lib/apt/lists/*
COPY deploy/image/closure.sh /usr/local/bin/closure.sh
RUN closure.sh /runtime /usr/local/bin/effectd /usr/bin/curl /usr/sbin/nginx /usr/bin/bash
COPY deploy/image/edge.sh /runtime/usr/local/bin/effectd-edge
COPY deploy/nginx/pod.conf /runtime/etc/effectd-edge/nginx.conf
COPY deploy/nginx/edge.conf /runtime/etc/effectd-edge/edge.conf

FROM scratch AS edge
COPY --from=edge-closure /runtime /
USER 10001
EXPOSE 8080 9090
ENV LP_NUM_THREADS=2 XDG_CACHE_HOME=/tmp/cache
HEALTHCHECK --interval=10s --timeout=3s --retries=3 CMD ["/usr/bin/curl", "-fsS", "http://127.0.0.1:8080/healthz"]
ENTRYPOINT ["/usr/local/bin/effectd-edge"]
