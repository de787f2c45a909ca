// An OpenXR API layer the XR tests build and put between incise and Monado, to make the
// runtime fail in the ways a real one can (issue 19, item 4). INCISE_XR_FAULT picks one:
//
//   create:N        xrCreateInstance fails with XrResult N (e.g. -6 INITIALIZATION_FAILED)
//   never-ready     the session's READY event is never delivered (the session stays IDLE)
//   vulkan-max:M.m  the runtime's Vulkan requirements say it was tested up to Vulkan M.m
//
// Anything else (or unset) passes every call through. Built with the OpenXR headers Monado
// bundles (src/external/openxr_includes): cc -shared -fPIC -I... fault_layer.c.

#define XR_USE_GRAPHICS_API_VULKAN
#include <vulkan/vulkan.h>
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>
#include <openxr/loader_interfaces.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LAYER_NAME "XR_APILAYER_INCISE_fault"

static PFN_xrGetInstanceProcAddr next_gipa;
static PFN_xrPollEvent next_poll_event;
static PFN_xrGetVulkanGraphicsRequirements2KHR next_vk_reqs2;
static PFN_xrGetVulkanGraphicsRequirementsKHR next_vk_reqs;

static const char *fault(void) {
    const char *f = getenv("INCISE_XR_FAULT");
    return f ? f : "";
}

static XRAPI_ATTR XrResult XRAPI_CALL poll_event(XrInstance instance, XrEventDataBuffer *event) {
    for (;;) {
        XrResult r = next_poll_event(instance, event);
        if (r != XR_SUCCESS || strcmp(fault(), "never-ready") != 0 ||
            event->type != XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
            return r;
        }
        const XrEventDataSessionStateChanged *e = (const XrEventDataSessionStateChanged *)event;
        if (e->state != XR_SESSION_STATE_READY) {
            return r;
        }
        fprintf(stderr, LAYER_NAME ": READY withheld\n");
    }
}

// "vulkan-max:M.m": the highest Vulkan version the runtime says it was tested with.
static void lower_max(XrVersion *max) {
    unsigned major, minor;
    if (sscanf(fault(), "vulkan-max:%u.%u", &major, &minor) == 2) {
        *max = XR_MAKE_VERSION(major, minor, 0);
    }
}

static XRAPI_ATTR XrResult XRAPI_CALL vk_reqs2(XrInstance instance, XrSystemId system,
                                               XrGraphicsRequirementsVulkanKHR *reqs) {
    XrResult r = next_vk_reqs2(instance, system, reqs);
    if (r == XR_SUCCESS) {
        lower_max(&reqs->maxApiVersionSupported);
    }
    return r;
}

static XRAPI_ATTR XrResult XRAPI_CALL vk_reqs(XrInstance instance, XrSystemId system,
                                              XrGraphicsRequirementsVulkanKHR *reqs) {
    XrResult r = next_vk_reqs(instance, system, reqs);
    if (r == XR_SUCCESS) {
        lower_max(&reqs->maxApiVersionSupported);
    }
    return r;
}

static XRAPI_ATTR XrResult XRAPI_CALL get_instance_proc_addr(XrInstance instance,
                                                             const char *name,
                                                             PFN_xrVoidFunction *function) {
    if (next_gipa == NULL) {
        return XR_ERROR_HANDLE_INVALID;
    }
    XrResult r = next_gipa(instance, name, function);
    if (r != XR_SUCCESS) {
        return r;
    }
    if (strcmp(name, "xrPollEvent") == 0) {
        next_poll_event = (PFN_xrPollEvent)*function;
        *function = (PFN_xrVoidFunction)poll_event;
    } else if (strcmp(name, "xrGetVulkanGraphicsRequirements2KHR") == 0) {
        next_vk_reqs2 = (PFN_xrGetVulkanGraphicsRequirements2KHR)*function;
        *function = (PFN_xrVoidFunction)vk_reqs2;
    } else if (strcmp(name, "xrGetVulkanGraphicsRequirementsKHR") == 0) {
        next_vk_reqs = (PFN_xrGetVulkanGraphicsRequirementsKHR)*function;
        *function = (PFN_xrVoidFunction)vk_reqs;
    }
    return XR_SUCCESS;
}

static XRAPI_ATTR XrResult XRAPI_CALL create_api_layer_instance(const XrInstanceCreateInfo *info,
                                                                const XrApiLayerCreateInfo *layer,
                                                                XrInstance *instance) {
    int code;
    if (sscanf(fault(), "create:%d", &code) == 1) {
        fprintf(stderr, LAYER_NAME ": xrCreateInstance fails with %d\n", code);
        return (XrResult)code;
    }
    if (layer == NULL || layer->nextInfo == NULL) {
        return XR_ERROR_INITIALIZATION_FAILED;
    }
    next_gipa = layer->nextInfo->nextGetInstanceProcAddr;
    XrApiLayerCreateInfo next = *layer;
    next.nextInfo = layer->nextInfo->next;
    return layer->nextInfo->nextCreateApiLayerInstance(info, &next, instance);
}

XRAPI_ATTR XrResult XRAPI_CALL xrNegotiateLoaderApiLayerInterface(
    const XrNegotiateLoaderInfo *loader, const char *name, XrNegotiateApiLayerRequest *request) {
    (void)name;
    if (loader == NULL || request == NULL ||
        loader->structType != XR_LOADER_INTERFACE_STRUCT_LOADER_INFO ||
        loader->minInterfaceVersion > XR_CURRENT_LOADER_API_LAYER_VERSION ||
        loader->maxInterfaceVersion < XR_CURRENT_LOADER_API_LAYER_VERSION) {
        return XR_ERROR_INITIALIZATION_FAILED;
    }
    request->layerInterfaceVersion = XR_CURRENT_LOADER_API_LAYER_VERSION;
    // Headers newer than the loader: claim no more than the loader knows.
    request->layerApiVersion = XR_CURRENT_API_VERSION < loader->maxApiVersion
                                   ? XR_CURRENT_API_VERSION
                                   : loader->maxApiVersion;
    request->getInstanceProcAddr = get_instance_proc_addr;
    request->createApiLayerInstance = create_api_layer_instance;
    return XR_SUCCESS;
}
