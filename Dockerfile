# Multi-stage: build with the same setup script as developers and CI; run as a non-root user.
FROM debian:bookworm AS build
WORKDIR /src
COPY scripts/setup.sh scripts/setup.sh
RUN scripts/setup.sh && rm -rf /var/lib/apt/lists/*
COPY . .
RUN BUILD_DIR=/build scripts/build.sh -DEFFECTD_TESTS=OFF -DEFFECTD_BENCH=OFF

FROM debian:bookworm-slim AS runtime
RUN apt-get update -qq \
 && apt-get install -y -qq --no-install-recommends \
      libcpp-httplib0.11 libopenimageio2.4 libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri curl ca-certificates \
 && rm -rf /var/lib/apt/lists/* \
 && useradd --system --uid 10001 --no-create-home effectd
COPY --from=build /build/server/effectd /usr/local/bin/effectd
USER 10001
EXPOSE 8080
ENV EFFECTD_HOST=0.0.0.0 EFFECTD_PORT=8080 LP_NUM_THREADS=2
HEALTHCHECK --interval=10s --timeout=3s --retries=3 CMD curl -fsS http://127.0.0.1:8080/healthz || exit 1
ENTRYPOINT ["/usr/local/bin/effectd"]
CMD ["serve"]
