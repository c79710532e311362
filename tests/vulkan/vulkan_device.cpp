#include "vulkan_device.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <spirv_cross/spirv_cross.hpp>

namespace effectd::vk {
namespace {

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(int(r)));
}

float halfToFloat(uint16_t h) {
  const int exponent = (h >> 10) & 0x1F, mantissa = h & 0x3FF;
  const float sign = (h & 0x8000) ? -1.0f : 1.0f;
  if (exponent == 0) return sign * std::ldexp(float(mantissa), -24);
  if (exponent == 31) return mantissa ? NAN : sign * INFINITY;
  return sign * std::ldexp(float(mantissa + 1024), exponent - 25);
}

size_t texelBytes(VkFormat f) {
  switch (f) {
    case VK_FORMAT_R8G8B8A8_UNORM: return 4;
    case VK_FORMAT_R16G16B16A16_SFLOAT: return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
    case VK_FORMAT_R32_SFLOAT: return 4;
    default: throw std::runtime_error("texelBytes: unsupported format");
  }
}

}  // namespace

Device::Device(int width, int height) : width_(width), height_(height) {
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "effectd vulkan test";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &app;
  check(vkCreateInstance(&ici, nullptr, &instance_), "vkCreateInstance");
  uint32_t n = 0;
  vkEnumeratePhysicalDevices(instance_, &n, nullptr);
  if (!n) throw std::runtime_error("no Vulkan device");
  std::vector<VkPhysicalDevice> devices(n);
  vkEnumeratePhysicalDevices(instance_, &n, devices.data());
  // A real GPU first, else the CPU (lavapipe).
  for (int pass = 0; pass < 2 && !physical_; ++pass)
    for (VkPhysicalDevice d : devices) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(d, &p);
      if ((pass == 0) == (p.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) && p.apiVersion >= VK_API_VERSION_1_1) {
        physical_ = d;
        name_ = p.deviceName;
        break;
      }
    }
  if (!physical_) throw std::runtime_error("no Vulkan 1.1 device");
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, families.data());
  family_ = UINT32_MAX;
  for (uint32_t i = 0; i < n; ++i)
    if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
      family_ = i;
      break;
    }
  if (family_ == UINT32_MAX) throw std::runtime_error("no graphics queue");
  const float priority = 1;
  VkDeviceQueueCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  qci.queueFamilyIndex = family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{};
  dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  check(vkCreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, family_, 0, &queue_);
  VkCommandPoolCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pci.queueFamilyIndex = family_;
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  check(vkCreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
  const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 64}, {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 64}};
  VkDescriptorPoolCreateInfo dpi{};
  dpi.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dpi.maxSets = 32;
  dpi.poolSizeCount = 2;
  dpi.pPoolSizes = sizes;
  check(vkCreateDescriptorPool(device_, &dpi, nullptr, &descriptors_), "vkCreateDescriptorPool");

  // The colour target and its render pass (cleared, then kept for the copy out).
  VkAttachmentDescription colour{};
  colour.format = VK_FORMAT_R16G16B16A16_SFLOAT;  // as the GL renderer's frame: blending beyond 1
  colour.samples = VK_SAMPLE_COUNT_1_BIT;
  colour.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  colour.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  colour.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  colour.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  colour.finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &ref;
  VkSubpassDependency after{};
  after.srcSubpass = 0;
  after.dstSubpass = VK_SUBPASS_EXTERNAL;
  after.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  after.dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  after.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  after.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo rpi{};
  rpi.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  rpi.attachmentCount = 1;
  rpi.pAttachments = &colour;
  rpi.subpassCount = 1;
  rpi.pSubpasses = &sub;
  rpi.dependencyCount = 1;
  rpi.pDependencies = &after;
  check(vkCreateRenderPass(device_, &rpi, nullptr, &pass_), "vkCreateRenderPass");
  VkImageCreateInfo ii{};
  ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  ii.extent = {uint32_t(width), uint32_t(height), 1};
  ii.mipLevels = ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  check(vkCreateImage(device_, &ii, nullptr, &target_.image), "vkCreateImage (target)");
  target_.memory = deviceMemory(target_.image);
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = target_.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = ii.format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  check(vkCreateImageView(device_, &vi, nullptr, &target_.view), "vkCreateImageView (target)");
  VkFramebufferCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  fi.renderPass = pass_;
  fi.attachmentCount = 1;
  fi.pAttachments = &target_.view;
  fi.width = uint32_t(width);
  fi.height = uint32_t(height);
  fi.layers = 1;
  check(vkCreateFramebuffer(device_, &fi, nullptr, &framebuffer_), "vkCreateFramebuffer");
}

Device::~Device() {
  if (!device_) {
    if (instance_) vkDestroyInstance(instance_, nullptr);
    return;
  }
  vkDeviceWaitIdle(device_);
  for (VkPipeline p : pipelines_) vkDestroyPipeline(device_, p, nullptr);
  for (VkPipelineLayout l : pipelineLayouts_) vkDestroyPipelineLayout(device_, l, nullptr);
  for (VkDescriptorSetLayout l : layouts_) vkDestroyDescriptorSetLayout(device_, l, nullptr);
  for (VkShaderModule m : modules_) vkDestroyShaderModule(device_, m, nullptr);
  for (Texture& t : textures_) {
    vkDestroySampler(device_, t.sampler, nullptr);
    vkDestroyImageView(device_, t.view, nullptr);
    vkDestroyImage(device_, t.image, nullptr);
    vkFreeMemory(device_, t.memory, nullptr);
  }
  for (Buffer& b : buffers_) vkDestroyBuffer(device_, b.buffer, nullptr), vkFreeMemory(device_, b.memory, nullptr);
  vkDestroyFramebuffer(device_, framebuffer_, nullptr);
  vkDestroyImageView(device_, target_.view, nullptr);
  vkDestroyImage(device_, target_.image, nullptr);
  vkFreeMemory(device_, target_.memory, nullptr);
  vkDestroyRenderPass(device_, pass_, nullptr);
  vkDestroyDescriptorPool(device_, descriptors_, nullptr);
  vkDestroyCommandPool(device_, pool_, nullptr);
  vkDestroyDevice(device_, nullptr);
  vkDestroyInstance(instance_, nullptr);
}

uint32_t Device::memoryType(uint32_t bits, VkMemoryPropertyFlags want) const {
  VkPhysicalDeviceMemoryProperties p;
  vkGetPhysicalDeviceMemoryProperties(physical_, &p);
  for (uint32_t i = 0; i < p.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (p.memoryTypes[i].propertyFlags & want) == want) return i;
  throw std::runtime_error("no suitable memory type");
}

VkDeviceMemory Device::deviceMemory(VkImage image) {
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device_, image, &req);
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkDeviceMemory memory;
  check(vkAllocateMemory(device_, &mai, nullptr, &memory), "vkAllocateMemory (image)");
  vkBindImageMemory(device_, image, memory, 0);
  return memory;
}

VkCommandBuffer Device::begin() {
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb;
  check(vkAllocateCommandBuffers(device_, &ai, &cb), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cb, &bi);
  return cb;
}

void Device::submit(VkCommandBuffer cb) {
  vkEndCommandBuffer(cb);
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  check(vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
  check(vkQueueWaitIdle(queue_), "vkQueueWaitIdle");
  vkFreeCommandBuffers(device_, pool_, 1, &cb);
}

// Host-visible and coherent: small test data, written once.
Buffer Device::buffer(const void* data, size_t bytes, VkBufferUsageFlags usage) {
  Buffer b;
  b.size = std::max<size_t>(bytes, 4);
  VkBufferCreateInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bi.size = b.size;
  bi.usage = usage;
  check(vkCreateBuffer(device_, &bi, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex =
      memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  check(vkAllocateMemory(device_, &mai, nullptr, &b.memory), "vkAllocateMemory");
  vkBindBufferMemory(device_, b.buffer, b.memory, 0);
  if (data && bytes) {
    void* p;
    vkMapMemory(device_, b.memory, 0, bytes, 0, &p);
    std::memcpy(p, data, bytes);
    vkUnmapMemory(device_, b.memory);
  }
  buffers_.push_back(b);
  return b;
}

Texture Device::texture(const TextureData& d) {
  Texture t;
  const bool cube = d.layers == 6;
  VkImageCreateInfo ii{};
  ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ii.flags = cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = d.format;
  ii.extent = {uint32_t(d.width), uint32_t(d.height), 1};
  ii.mipLevels = 1;
  ii.arrayLayers = uint32_t(d.layers);
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  check(vkCreateImage(device_, &ii, nullptr, &t.image), "vkCreateImage");
  t.memory = deviceMemory(t.image);
  const size_t expected = size_t(d.width) * size_t(d.height) * size_t(d.layers) * texelBytes(d.format);
  if (d.bytes.size() != expected) throw std::runtime_error("texture data has the wrong size");
  Buffer staging = buffer(d.bytes.data(), d.bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  VkCommandBuffer cb = begin();
  VkImageMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = t.image;
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, uint32_t(d.layers)};
  barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr,
                       1, &barrier);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, uint32_t(d.layers)};
  copy.imageExtent = ii.extent;
  vkCmdCopyBufferToImage(cb, staging.buffer, t.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
  barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0, nullptr, 0,
                       nullptr, 1, &barrier);
  submit(cb);
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = t.image;
  vi.viewType = cube ? VK_IMAGE_VIEW_TYPE_CUBE : VK_IMAGE_VIEW_TYPE_2D;
  vi.format = d.format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, uint32_t(d.layers)};
  check(vkCreateImageView(device_, &vi, nullptr, &t.view), "vkCreateImageView");
  VkSamplerCreateInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  si.magFilter = si.minFilter = VK_FILTER_LINEAR;
  si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  si.addressModeU = d.repeatU ? VK_SAMPLER_ADDRESS_MODE_REPEAT : VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  si.maxLod = 0;
  check(vkCreateSampler(device_, &si, nullptr, &t.sampler), "vkCreateSampler");
  textures_.push_back(t);
  return t;
}

VkDescriptorSetLayout Device::setLayout(const std::map<uint32_t, VkDescriptorType>& bindings) {
  std::vector<VkDescriptorSetLayoutBinding> b;
  for (const auto& [binding, type] : bindings)
    b.push_back({binding, type, 1, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, nullptr});
  VkDescriptorSetLayoutCreateInfo li{};
  li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  li.bindingCount = uint32_t(b.size());
  li.pBindings = b.data();
  VkDescriptorSetLayout layout;
  check(vkCreateDescriptorSetLayout(device_, &li, nullptr, &layout), "vkCreateDescriptorSetLayout");
  layouts_.push_back(layout);
  VkPipelineLayoutCreateInfo pli{};
  pli.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &layout;
  VkPipelineLayout pl;
  check(vkCreatePipelineLayout(device_, &pli, nullptr, &pl), "vkCreatePipelineLayout");
  pipelineLayouts_.push_back(pl);
  layoutOf_[layout] = pl;
  return layout;
}

VkShaderModule Device::module(const std::vector<uint32_t>& words) {
  VkShaderModuleCreateInfo mi{};
  mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  mi.codeSize = words.size() * 4;
  mi.pCode = words.data();
  VkShaderModule m;
  check(vkCreateShaderModule(device_, &mi, nullptr, &m), "vkCreateShaderModule");
  modules_.push_back(m);
  return m;
}

VkPipeline Device::pipeline(const std::vector<uint32_t>& vertexSpirv, const std::vector<uint32_t>& fragmentSpirv,
                            const std::vector<Attribute>& attributes, VkDescriptorSetLayout layout,
                            const PipelineState& state) {
  VkPipelineShaderStageCreateInfo stages[2] = {};
  stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = module(vertexSpirv);
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = module(fragmentSpirv);
  stages[1].pName = "main";
  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attrs;
  for (uint32_t i = 0; i < attributes.size(); ++i) {
    bindings.push_back({i, attributes[i].components * 4, VK_VERTEX_INPUT_RATE_VERTEX});
    const VkFormat f = attributes[i].components == 2   ? VK_FORMAT_R32G32_SFLOAT
                       : attributes[i].components == 3 ? VK_FORMAT_R32G32B32_SFLOAT
                                                       : VK_FORMAT_R32G32B32A32_SFLOAT;
    attrs.push_back({attributes[i].location, i, f, 0});
  }
  VkPipelineVertexInputStateCreateInfo vin{};
  vin.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  vin.vertexBindingDescriptionCount = uint32_t(bindings.size());
  vin.pVertexBindingDescriptions = bindings.data();
  vin.vertexAttributeDescriptionCount = uint32_t(attrs.size());
  vin.pVertexAttributeDescriptions = attrs.data();
  VkPipelineInputAssemblyStateCreateInfo ia{};
  ia.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  // GL's conventions: y up through a negative viewport height (Vulkan 1.1), counter-clockwise front.
  VkViewport viewport{0, float(height_), float(width_), -float(height_), 0, 1};
  VkRect2D scissor{{0, 0}, {uint32_t(width_), uint32_t(height_)}};
  VkPipelineViewportStateCreateInfo vp{};
  vp.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  vp.viewportCount = 1;
  vp.pViewports = &viewport;
  vp.scissorCount = 1;
  vp.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo rs{};
  rs.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = state.cull;
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1;
  VkPipelineMultisampleStateCreateInfo ms{};
  ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineColorBlendAttachmentState blend{};
  blend.blendEnable = state.blend;
  blend.srcColorBlendFactor = state.srcColor;
  blend.dstColorBlendFactor = state.dstColor;
  blend.colorBlendOp = VK_BLEND_OP_ADD;
  blend.srcAlphaBlendFactor = state.srcAlpha;
  blend.dstAlphaBlendFactor = state.dstAlpha;
  blend.alphaBlendOp = VK_BLEND_OP_ADD;
  blend.colorWriteMask = 0xF;
  VkPipelineColorBlendStateCreateInfo cbs{};
  cbs.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  cbs.attachmentCount = 1;
  cbs.pAttachments = &blend;
  VkGraphicsPipelineCreateInfo gi{};
  gi.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  gi.stageCount = 2;
  gi.pStages = stages;
  gi.pVertexInputState = &vin;
  gi.pInputAssemblyState = &ia;
  gi.pViewportState = &vp;
  gi.pRasterizationState = &rs;
  gi.pMultisampleState = &ms;
  gi.pColorBlendState = &cbs;
  gi.layout = layoutOf_.at(layout);
  gi.renderPass = pass_;
  VkPipeline p;
  check(vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &gi, nullptr, &p), "vkCreateGraphicsPipelines");
  pipelines_.push_back(p);
  return p;
}

VkDescriptorSet Device::descriptorSet(VkDescriptorSetLayout layout, const std::map<uint32_t, const Buffer*>& uniforms,
                                      const std::map<uint32_t, const Texture*>& textures) {
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = descriptors_;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &layout;
  VkDescriptorSet set;
  check(vkAllocateDescriptorSets(device_, &ai, &set), "vkAllocateDescriptorSets");
  std::vector<VkDescriptorBufferInfo> bufferInfo;
  std::vector<VkDescriptorImageInfo> imageInfo;
  bufferInfo.reserve(uniforms.size());
  imageInfo.reserve(textures.size());
  std::vector<VkWriteDescriptorSet> writes;
  auto write = [&](uint32_t binding, VkDescriptorType type) -> VkWriteDescriptorSet& {
    VkWriteDescriptorSet& w = writes.emplace_back();
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = type;
    return w;
  };
  for (const auto& [binding, b] : uniforms) {
    bufferInfo.push_back({b->buffer, 0, b->size});
    write(binding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER).pBufferInfo = &bufferInfo.back();
  }
  for (const auto& [binding, t] : textures) {
    imageInfo.push_back({t->sampler, t->view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    write(binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER).pImageInfo = &imageInfo.back();
  }
  vkUpdateDescriptorSets(device_, uint32_t(writes.size()), writes.data(), 0, nullptr);
  return set;
}

std::vector<uint8_t> Device::render(const float clear[4], const std::vector<Draw>& draws) {
  Buffer out = buffer(nullptr, size_t(width_) * size_t(height_) * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  VkCommandBuffer cb = begin();
  VkClearValue cv;
  std::memcpy(cv.color.float32, clear, sizeof(float) * 4);
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = pass_;
  rb.framebuffer = framebuffer_;
  rb.renderArea = {{0, 0}, {uint32_t(width_), uint32_t(height_)}};
  rb.clearValueCount = 1;
  rb.pClearValues = &cv;
  vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
  for (const Draw& d : draws) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, d.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layoutOf_.at(d.layout), 0, 1, &d.set, 0, nullptr);
    std::vector<VkBuffer> vbs;
    std::vector<VkDeviceSize> offsets;
    for (const Buffer& b : *d.attributes) vbs.push_back(b.buffer), offsets.push_back(0);
    vkCmdBindVertexBuffers(cb, 0, uint32_t(vbs.size()), vbs.data(), offsets.data());
    vkCmdBindIndexBuffer(cb, d.indices->buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cb, d.indexCount, 1, 0, 0, 0);
  }
  vkCmdEndRenderPass(cb);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {uint32_t(width_), uint32_t(height_), 1};
  vkCmdCopyImageToBuffer(cb, target_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out.buffer, 1, &copy);
  VkBufferMemoryBarrier host{};
  host.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  host.srcQueueFamilyIndex = host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  host.buffer = out.buffer;
  host.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &host, 0, nullptr);
  submit(cb);
  std::vector<uint16_t> halves(size_t(width_) * size_t(height_) * 4);
  void* p;
  vkMapMemory(device_, out.memory, 0, halves.size() * 2, 0, &p);
  std::memcpy(halves.data(), p, halves.size() * 2);
  vkUnmapMemory(device_, out.memory);
  // To 8 bits as the preview's PNG: round(255 x), clamped.
  std::vector<uint8_t> pixels(halves.size());
  for (size_t i = 0; i < halves.size(); ++i)
    pixels[i] = uint8_t(std::lround(std::clamp(halfToFloat(halves[i]), 0.0f, 1.0f) * 255.0f));
  return pixels;  // row 0 is the top: the flipped viewport put GL's y = 1 there
}

BlockLayout::BlockLayout(const std::vector<uint32_t>& spirv) {
  spirv_cross::Compiler c(spirv);
  const spirv_cross::ShaderResources r = c.get_shader_resources();
  if (r.uniform_buffers.empty()) return;
  const spirv_cross::Resource& block = r.uniform_buffers.front();
  const spirv_cross::SPIRType& type = c.get_type(block.base_type_id);
  size_ = c.get_declared_struct_size(type);
  for (uint32_t i = 0; i < type.member_types.size(); ++i) {
    const spirv_cross::SPIRType& m = c.get_type(type.member_types[i]);
    Member out;
    out.offset = c.type_struct_member_offset(type, i);
    out.components = m.vecsize;
    out.columns = m.columns;
    out.integer = m.basetype == spirv_cross::SPIRType::Int || m.basetype == spirv_cross::SPIRType::UInt;
    if (!m.array.empty()) out.arraySize = m.array[0], out.arrayStride = c.type_struct_member_array_stride(type, i);
    if (m.columns > 1) out.matrixStride = c.type_struct_member_matrix_stride(type, i);
    members_[c.get_member_name(block.base_type_id, i)] = out;
  }
}

void BlockLayout::fill(std::vector<uint8_t>& out, const std::string& member, const std::vector<double>& values) const {
  const Member& m = members_.at(member);
  out.resize(std::max(out.size(), size_));
  size_t k = 0;
  for (uint32_t e = 0; e < m.arraySize; ++e)
    for (uint32_t col = 0; col < m.columns; ++col)
      for (uint32_t row = 0; row < m.components; ++row, ++k) {
        if (k >= values.size()) return;
        const size_t at = m.offset + e * m.arrayStride + col * m.matrixStride + row * 4;
        if (m.integer) {
          const int32_t v = int32_t(values[k]);
          std::memcpy(&out[at], &v, 4);
        } else {
          const float v = float(values[k]);
          std::memcpy(&out[at], &v, 4);
        }
      }
}

std::vector<std::string> BlockLayout::names() const {
  std::vector<std::string> n;
  for (const auto& [name, m] : members_) n.push_back(name);
  return n;
}

}  // namespace effectd::vk
