//! The user's room behind the organ on a Quest (`XR_FB_passthrough`): a running
//! passthrough and a full-screen reconstruction layer submitted under the projection
//! layer.

use ::openxr as xr;

use super::error::{XrError, xr_call};

/// A started passthrough and its layer.
pub struct XrPassthrough {
    layer: xr::PassthroughLayerFB,
    _passthrough: xr::Passthrough,
}

impl XrPassthrough {
    /// Start passthrough on `session` (the instance must have `XR_FB_passthrough`).
    pub fn start(session: &xr::Session<xr::Vulkan>) -> Result<Self, XrError> {
        let passthrough = session
            .create_passthrough(xr::PassthroughFlagsFB::IS_RUNNING_AT_CREATION)
            .map_err(xr_call("xrCreatePassthroughFB"))?;
        let layer = session
            .create_passthrough_layer(
                &passthrough,
                xr::PassthroughFlagsFB::IS_RUNNING_AT_CREATION,
                xr::PassthroughLayerPurposeFB::RECONSTRUCTION,
            )
            .map_err(xr_call("xrCreatePassthroughLayerFB"))?;
        Ok(XrPassthrough {
            layer,
            _passthrough: passthrough,
        })
    }

    /// The composition layer to submit first each frame (`XrCompositionLayerPassthroughFB`;
    /// openxr 0.22 does not export its builder, so it is built from the raw struct).
    pub fn composition_layer(&self) -> PassthroughComposition {
        PassthroughComposition(xr::sys::CompositionLayerPassthroughFB {
            ty: xr::sys::CompositionLayerPassthroughFB::TYPE,
            next: std::ptr::null(),
            flags: xr::CompositionLayerFlags::EMPTY,
            space: xr::sys::Handle::NULL,
            layer_handle: self.layer.as_raw(),
        })
    }
}

/// A passthrough composition layer, ready to submit.
pub struct PassthroughComposition(xr::sys::CompositionLayerPassthroughFB);

impl PassthroughComposition {
    /// The layer as the base type `xrEndFrame` takes.
    pub fn base(&self) -> &xr::CompositionLayerBase<'_, xr::Vulkan> {
        // SAFETY: `CompositionLayerBase` is `repr(transparent)` over
        // `XrCompositionLayerBaseHeader`, whose fields (type, next, flags, space) begin
        // every composition layer struct; openxr's own layer builders deref the same way.
        unsafe { &*(&self.0 as *const xr::sys::CompositionLayerPassthroughFB).cast() }
    }
}
