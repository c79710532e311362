-- wrk: a mixed load of valid requests, one of each in turn (per wrk thread).
local requests = {
  { "/v1/fog", '{"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":256}}' },
  { "/v1/fog", '{"fog":{"fogType":"HEIGHT","density":0.1,"heightFalloff":0.3},"table":{"size":64,"elevations":16}}' },
  { "/v1/lightning", '{"grid":{"width":64,"height":64},"start":[32,0],"targets":[[32,63]],"seed":3}' },
  { "/v1/tangents", '{"mesh":{"positions":[0,0,0,1,0,0,1,1,0,0,1,0],"uvs":[0,0,1,0,1,1,0,1],"indices":[0,1,2,0,2,3]}}' },
  { "/v1/bubble", '{"time":12.5,"include":["uniforms","shader"]}' },
  { "/v1/scene", '{"fog":{"fog":{"fogType":"GL_EXP","density":0.1}},"bubble":{"include":["uniforms"]}}' },
  { "/v1/render", '{"width":64,"height":64,"fog":{"fog":{"fogType":"GL_EXP","density":0.1}},"quads":[{"center":[0,0,0],"size":[2,2]}]}' },
}
local i = 0
request = function()
  i = i % #requests + 1
  return wrk.format("POST", requests[i][1], { ["Content-Type"] = "application/json" }, requests[i][2])
end
